#include "tests/bench/e2e/process_usage.hpp"

#include <unistd.h>

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rsg::bench {
namespace {

std::string proc_file(pid_t pid, const char* name) { return "/proc/" + std::to_string(pid) + "/" + name; }

double cpu_seconds_of(pid_t pid) {
  std::ifstream in(proc_file(pid, "stat"));
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(proc_file(pid, "stat") + ": process gone");
  // The command name (field 2) is in parentheses and may contain spaces: count from the last ')'.
  std::istringstream fields(line.substr(line.rfind(')') + 2));
  std::string skipped;
  for (int field = 3; field < 14; ++field) fields >> skipped;  // state .. cmajflt
  unsigned long long utime = 0, stime = 0;
  fields >> utime >> stime;
  return static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

std::int64_t rss_kb_of(pid_t pid) {
  std::ifstream in(proc_file(pid, "status"));
  for (std::string line; std::getline(in, line);)
    if (line.starts_with("VmRSS:")) return std::stoll(line.substr(6));
  throw std::runtime_error(proc_file(pid, "status") + ": no VmRSS (process gone?)");
}

}  // namespace

ProcessUsage read_usage(pid_t pid) { return {Clock::now(), cpu_seconds_of(pid), rss_kb_of(pid)}; }

std::uint64_t udp_receive_buffer_drops() {
  // Two "Udp:" lines: the column names, then the values.
  std::ifstream in("/proc/net/snmp");
  std::string names, values;
  for (std::string line; std::getline(in, line);)
    if (line.starts_with("Udp:")) (names.empty() ? names : values) = line;
  std::istringstream name_fields(names), value_fields(values);
  for (std::string name, value; name_fields >> name && value_fields >> value;)
    if (name == "RcvbufErrors") return std::stoull(value);
  return 0;
}

double cpu_percent(const ProcessUsage& from, const ProcessUsage& to) {
  const double wall = std::chrono::duration<double>(to.at - from.at).count();
  return wall > 0 ? 100.0 * (to.cpu_seconds - from.cpu_seconds) / wall : 0.0;
}

}  // namespace rsg::bench
