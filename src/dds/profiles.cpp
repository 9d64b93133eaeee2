#include "rsg/dds/profiles.hpp"

#include <tinyxml2.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <stdexcept>
#include <vector>

#include "dds/internal/fastdds_compat.hpp"
#include "dds/internal/fastdds_log.hpp"
#include "rsg/error.hpp"

namespace rsg::dds {
namespace {

// Fast DDS logs through its own consumers, by default to stdout, where a tool's output goes (rsg_echo
// --json, rsg_frame), and from a thread of its own, after whatever the caller printed meanwhile.
// Its warnings and errors go to stderr here, like everything else a program says, without terminal
// colour codes unless stderr is a terminal (internal/fastdds_log.hpp).
void fastdds_log_to_stderr() {
  static const bool done = [] {
    namespace fdds = eprosima::fastdds::dds;
    fdds::Log::ClearConsumers();
    fdds::Log::RegisterConsumer(internal::StderrLogConsumer::for_stderr());  // colour on a terminal only
    return true;
  }();
  (void)done;
}

// Fast DDS says only "Error opening" or "Error parsing" for a file that is not well-formed XML:
// tinyxml2 (which Fast DDS parses with) names the line and what is wrong.
void check_well_formed(const std::filesystem::path& file) {
  tinyxml2::XMLDocument document;
  if (document.LoadFile(file.c_str()) == tinyxml2::XML_SUCCESS) return;
  std::string what = document.ErrorName();
  if (const char* detail = document.ErrorStr(); detail != nullptr) {
    // ErrorStr() reads "Error=XML_ERROR_... ErrorID=7 (0x7) Line number=3: what": keep the what.
    const std::string text = detail;
    const auto colon = text.find(": ");
    if (colon != std::string::npos) what += ": " + text.substr(colon + 2);
  }
  const int line = document.ErrorLineNum();
  throw InputError(file.string() + (line > 0 ? ":" + std::to_string(line) : "") + ": not well-formed XML (" +
                   what + ")");
}

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
  fastdds_log_to_stderr();
  for (const auto& file : files) {
    check_well_formed(file);
    if (internal::load_xml_profiles_file(file.string()) != kOk) {
      eprosima::fastdds::dds::Log::Flush();  // its reasons first, then this line
      throw InputError(file.string() +
                       ": Fast DDS rejected this XML profile file (the XMLPARSER lines above say why)");
    }
  }
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
