#include "rsg/dds/profiles.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <stdexcept>
#include <vector>

#include "rsg/dds/detail/fastdds_compat.hpp"
#include "rsg/error.hpp"

namespace rsg::dds {
namespace {

std::filesystem::path running_binary_dir() {
  std::error_code error;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::filesystem::path() : self.parent_path();
}

}  // namespace

std::filesystem::path default_profiles_dir() {
  if (const char* env = std::getenv("RSG_PROFILES_DIR"); env && *env) return env;
  const auto bin = running_binary_dir();
  // Installed: <prefix>/bin + <prefix>/share/rsg/xml_profiles. Docker image: /opt/rsg/{bin,xml_profiles}.
  for (const auto& candidate : {bin / "../share/rsg/xml_profiles", bin / "../xml_profiles"}) {
    std::error_code error;
    if (std::filesystem::is_directory(candidate, error)) return std::filesystem::weakly_canonical(candidate);
  }
  // A build tree uses the sources it was built from; a program linking the installed library, the
  // profiles installed with it.
  std::error_code error;
  if (std::filesystem::is_directory(RSG_SOURCE_PROFILES_DIR, error)) return RSG_SOURCE_PROFILES_DIR;
  return RSG_INSTALLED_PROFILES_DIR;
}

void load_profiles(const std::filesystem::path& file_or_dir) {
  std::vector<std::filesystem::path> files;
  std::error_code error;
  if (std::filesystem::is_directory(file_or_dir, error)) {
    for (const auto& entry : std::filesystem::directory_iterator(file_or_dir))
      if (entry.path().extension() == ".xml") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
  } else if (std::filesystem::is_regular_file(file_or_dir, error)) {
    files.push_back(file_or_dir);
  }
  if (files.empty()) throw InputError(file_or_dir.string() + ": no XML profiles found");
  for (const auto& file : files)
    if (load_xml_profiles_file(file.string()) != kOk)
      throw InputError(file.string() +
                       ": Fast DDS rejected this XML profile file (its log above says where)");
}

void load_profiles(const std::vector<std::string>& files_or_dirs, const std::string& participant_profile) {
  if (files_or_dirs.empty()) load_profiles(default_profiles_dir());
  for (const auto& file_or_dir : files_or_dirs) load_profiles(file_or_dir);
  eprosima::fastdds::dds::DomainParticipantQos unused;
  if (eprosima::fastdds::dds::DomainParticipantFactory::get_instance()->get_participant_qos_from_profile(
          participant_profile, unused) != kOk)
    throw InputError("no participant profile named '" + participant_profile + "'");
}

}  // namespace rsg::dds
