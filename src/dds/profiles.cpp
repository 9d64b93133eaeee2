#include "rsg/dds/profiles.hpp"

#include <tinyxml2.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/log/StdoutErrConsumer.hpp>
#include <optional>
#include <stdexcept>
#include <string>
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

// The text of `element` without the white space around it ("" for none).
std::string trimmed_text(const tinyxml2::XMLElement& element) {
  const char* text = element.GetText();
  std::string value = text ? text : "";
  const auto first = value.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return "";
  return value.substr(first, value.find_last_not_of(" \t\r\n") - first + 1);
}

// A whole number in decimal (an optional sign) or in hexadecimal after 0x, as TinyXML-2
// reads numbers for Fast DDS; nothing else (not "12abc", which its sscanf would read as 12).
std::optional<long long> whole_number(const std::string& text) {
  std::size_t at = 0;
  int base = 10;
  bool negative = false;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;
    at = 2;
  } else if (!text.empty() && (text[0] == '-' || text[0] == '+')) {
    negative = text[0] == '-';
    at = 1;
  }
  if (at == text.size() || text.size() - at > 12) return std::nullopt;  // 12 digits: far beyond 2^32
  long long value = 0;
  for (; at < text.size(); ++at) {
    const char c = text[at];
    int digit = -1;
    if (c >= '0' && c <= '9') {
      digit = c - '0';
    } else if (base == 16 && c >= 'a' && c <= 'f') {
      digit = c - 'a' + 10;
    } else if (base == 16 && c >= 'A' && c <= 'F') {
      digit = c - 'A' + 10;
    }
    if (digit < 0) return std::nullopt;
    value = value * base + digit;
  }
  return negative ? -value : value;
}

// Fast DDS's duration keywords (its XML schema's durationType): the whole duration is infinite.
bool infinite_keyword(const std::string& text) {
  return text == "DURATION_INFINITY" || text == "DURATION_INFINITE_SEC" || text == "DURATION_INFINITE_NSEC";
}

// Every duration of the file (an element with <sec> or <nanosec> children) is one Fast DDS can
// represent: infinite, or whole seconds from 0 to 2^31 - 1 and nanoseconds below 10^9, the rule of
// Fast DDS's own fix (its QoS consistency check since 2.6.12 / 3.2.5 / 3.4.3 / 3.6.2). Fast DDS
// before it loads <nanosec>1000000000</nanosec> and then loops forever in Time_t::fraction() as
// soon as it serializes that duration (CVE-2025-63829): a participant's lease duration in its
// first announcement, a writer's or reader's QoS in its discovery data. A negative <sec> it takes
// as it is. Both are refused here, before Fast DDS sees the file.
void check_durations(const tinyxml2::XMLNode& parent, const std::filesystem::path& file) {
  for (const auto* element = parent.FirstChildElement(); element; element = element->NextSiblingElement()) {
    // Every <sec> and <nanosec> of the duration, with its value: Fast DDS takes the last of each.
    struct Part {
      const tinyxml2::XMLElement* element;
      bool is_sec;
      std::string text;
      std::string where;
    };
    std::vector<Part> parts;
    for (const auto* part = element->FirstChildElement(); part; part = part->NextSiblingElement()) {
      const std::string name = part->Name();
      if (name != "sec" && name != "nanosec") continue;
      const std::string text = trimmed_text(*part);
      parts.push_back({part, name == "sec", text,
                       file.string() + ":" + std::to_string(part->GetLineNum()) + ": <" + element->Name() +
                           "> <" + name + ">" + text + "</" + name + ">: "});
    }
    if (parts.empty()) {
      check_durations(*element, file);
      continue;
    }
    if (std::any_of(parts.begin(), parts.end(), [](const Part& part) { return infinite_keyword(part.text); }))
      continue;
    long long seconds = 0;
    long long nanoseconds = 0;
    for (const Part& part : parts) {
      const auto value = whole_number(part.text);
      if (!value)
        throw InputError(part.where + "not a whole number of " + (part.is_sec ? "seconds" : "nanoseconds"));
      if (part.is_sec && (*value < 0 || *value > 0x7fffffff))
        throw InputError(part.where + "seconds must be from 0 to 2147483647, or DURATION_INFINITY");
      if (!part.is_sec && (*value < 0 || *value > 0xffffffff))
        throw InputError(part.where + "nanoseconds must be from 0 to 999999999");
      (part.is_sec ? seconds : nanoseconds) = *value;
    }
    if (seconds == 0x7fffffff && nanoseconds == 0xffffffff) continue;  // Fast DDS's infinite, spelt out
    for (const Part& part : parts) {
      if (!part.is_sec && *whole_number(part.text) >= 1000000000)
        throw InputError(
            part.where +
            "nanoseconds must be from 0 to 999999999 (whole seconds go in <sec>; Fast DDS before its "
            "fix of CVE-2025-63829 loops forever on such a duration)");
    }
  }
}

// Fast DDS says only "Error opening" or "Error parsing" for a file that is not well-formed XML:
// tinyxml2 (which Fast DDS parses with) names the line and what is wrong. A well-formed file's
// durations are then checked (check_durations).
void check_profile_file(const std::filesystem::path& file) {
  tinyxml2::XMLDocument document;
  if (document.LoadFile(file.c_str()) == tinyxml2::XML_SUCCESS) {
    check_durations(document, file);
    return;
  }
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
    check_profile_file(file);
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
