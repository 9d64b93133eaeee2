// CPU time and resident memory of a process, as the kernel accounts them in /proc/PID.
#pragma once

#include <sys/types.h>

#include <cstdint>

#include "tests/bench/e2e/stamped_frames.hpp"

namespace rsg::bench {

struct ProcessUsage {
  Clock::time_point at;
  double cpu_seconds = 0;   ///< utime + stime: user and kernel time of all its threads
  std::int64_t rss_kb = 0;  ///< VmRSS
};

/// Reads /proc/PID/stat and /proc/PID/status. Throws std::runtime_error when the process is gone.
ProcessUsage read_usage(pid_t pid);

/// CPU time between two readings as a percentage of one core's wall time.
double cpu_percent(const ProcessUsage& from, const ProcessUsage& to);

/// Datagrams the kernel dropped so far because a UDP socket's receive buffer was full, on the
/// whole host (Udp RcvbufErrors in /proc/net/snmp): where loss happened, when frames go missing.
std::uint64_t udp_receive_buffer_drops();

}  // namespace rsg::bench
