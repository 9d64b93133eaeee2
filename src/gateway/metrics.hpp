// The gateway's counters in Prometheus' text exposition format (version 0.0.4), served on
// `--metrics HOST:PORT` by metrics_server.hpp, and the health verdict of its `/healthz`.
//
// The ingress thread takes a MetricsSnapshot once per status period and on every link change;
// the server's thread formats it when a scraper asks. Nothing here runs per frame.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gateway/clock.hpp"
#include "gateway/latency_histogram.hpp"
#include "rsg/dds/rtps_guard.hpp"
#include "status/stats.hpp"

namespace rsg::gateway {

/// The flight recorder's dumps since start, by how they ended (DumpWriter).
struct DumpCounts {
  std::uint64_t written = 0;
  std::uint64_t failed = 0;         ///< the file could not be written
  std::uint64_t refused = 0;        ///< not taken: earlier dumps were still being written
  std::uint64_t throttled = 0;      ///< not taken: sooner than --pcap-min-interval after the last
  std::uint64_t files_deleted = 0;  ///< oldest files deleted for --pcap-max-files / --pcap-max-mb
  std::uint64_t not_kept = 0;       ///< datagrams from outside --allow-from left out of the ring
};

/// SIGHUP's reloads of the configuration since start (Gateway::reload).
struct ReloadCounts {
  std::uint64_t applied = 0;
  std::uint64_t failed = 0;  ///< the file did not read or check: the running configuration stayed
};

/// What the transport guard of the gateway's participant did (rsg/dds/rtps_guard.hpp).
struct DdsGuardCounts {
  std::uint64_t statistics_removed = 0;
  std::uint64_t statistics_misplaced = 0;
  std::uint64_t send_channels_opened = 0;
  std::uint64_t destinations_skipped = 0;
  std::uint64_t announcements_refused = 0;
  std::uint64_t leases_shortened = 0;
  /// Messages the RTPS screen refused, by dds::RtpsScreenReason.
  std::array<std::uint64_t, dds::kRtpsScreenReasons> screened_out{};
};

/// What one scrape reports: the gateway's counters as of the last status period or link change.
struct MetricsSnapshot {
  status::GatewayStats stats;
  bool has_ingress = false;
  std::optional<DumpCounts> dumps;  ///< with a flight recorder (--pcap-ring)
  DdsGuardCounts dds_guard;
  LatencyHistogram ingress_delay;  ///< with ingress: arrival -> publication, every valid frame
  LatencyHistogram frame_age;      ///< with ingress: the robot's time stamp -> publication (Ingress)
  ReloadCounts reloads;
  /// Unix time (s) of the last link change; the gateway's start before the first.
  double link_last_change_s = 0;
  /// The labels every series carries: `gateway` always (the gateway sets it to --name, the
  /// partition or the host's name), `partition` unless empty.
  std::string gateway;
  std::string partition;
  std::string version;          ///< rsg's (the CMake project version)
  std::string fastdds_version;  ///< the Fast DDS rsg was built with
  Clock::time_point taken{};    ///< when the ingress thread took it
};

/// The process's own figures, read when a scraper asks (not by the ingress thread).
struct ProcessFigures {
  double cpu_seconds = 0;     ///< user + system
  double resident_bytes = 0;  ///< resident set size
  double start_time_s = 0;    ///< Unix time the process started
  double open_fds = 0;
};

/// The calling process's figures from getrusage and /proc/self; nothing when /proc cannot be read.
std::optional<ProcessFigures> read_process_figures();

/// The exposition text: # HELP and # TYPE of every family, then its samples. Counters end in
/// `_total`, durations are in seconds, every series carries the snapshot's labels.
std::string format_metrics(const MetricsSnapshot& snapshot, const std::optional<ProcessFigures>& process);

/// The names of every metric family `format_metrics` writes (for the dashboard check).
std::vector<std::string> metric_family_names();

/// /livez: the process is alive, i.e. its loop still hands over snapshots: the snapshot is no older
/// than `max_age` (one that stops coming means the loop that takes it is stuck). Says nothing of the
/// robot: a gateway waiting for its robot is alive.
bool is_live(const MetricsSnapshot& snapshot, Clock::time_point now, Clock::duration max_age);

/// /readyz (and /healthz, its older name): alive, and valid frames arrive within the link deadline,
/// i.e. the robot streams into DDS (the participant and writers exist from the start). A gateway
/// without ingress is ready while it is alive.
bool is_ready(const MetricsSnapshot& snapshot, Clock::time_point now, Clock::duration max_age);

/// A label value escaped for the exposition format (backslash, double quote, line feed).
std::string escape_label_value(std::string_view value);

}  // namespace rsg::gateway
