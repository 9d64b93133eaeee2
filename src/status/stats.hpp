// The gateway's counters, and the two text forms of their snapshot: the `--stats-file` JSON and
// the periodic log line. The DDS form is the GatewayStatus topic (status_publisher.hpp).
//
// Each counter has a single writer thread: ingress counters belong to the receive loop, egress
// counters to the egress thread (which publishes them through relaxed atomics).
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "rsg/wire/error.hpp"
#include "status/sequence_tracker.hpp"

namespace rsg::status {

/// Per spec validation category (ErrorCategory::kTruncated first), `kNone` excluded.
using InvalidCounts = std::array<std::uint64_t, wire::kErrorCategoryCount>;

constexpr std::size_t invalid_index(wire::ErrorCategory category) {
  return static_cast<std::size_t>(category) - 1;
}
constexpr wire::ErrorCategory category_at(std::size_t index) {
  return static_cast<wire::ErrorCategory>(index + 1);
}

struct IngressCounters {
  std::uint64_t received = 0;  ///< datagrams from allowed sources, valid or not
  std::uint64_t published = 0;
  std::uint64_t publish_failed = 0;  ///< valid frames DDS refused to write
  std::uint64_t rejected_source = 0;
  InvalidCounts invalid{};

  std::uint64_t invalid_total() const;
};

struct EgressCounters {
  std::uint64_t samples = 0;      ///< samples taken from the egress topic
  std::uint64_t frames_sent = 0;  ///< datagrams sent, one per sample and destination
  std::uint64_t unencodable = 0;  ///< samples that do not describe a valid frame
  std::uint64_t send_failed = 0;
  /// Samples not sent because the robot would read their frame as a selection request (L = 0).
  std::uint64_t request_like = 0;
  /// Samples not sent because egress was at its rate limit (--egress-rate).
  std::uint64_t rate_limited = 0;
};

struct GatewayStats {
  IngressCounters ingress;
  std::uint32_t state_readers = 0;   ///< readers matched by the RobotState writer
  std::uint32_t egress_writers = 0;  ///< writers matched by the egress reader
  /// Readers matched by the ROS 2 standard topics' writers (joint_states, tf, external_wrench),
  /// summed: the writers' side of discovery, which a test waits for before the robot sends.
  std::uint32_t standard_readers = 0;
  /// Writers of the gateway's state topic in its partition that belong to other programs: another
  /// robot's gateway with the same partition (its readers get both robots' samples interleaved), a
  /// replay. 0 unless robots are mixed. In the metrics, /readyz and the status line; not in
  /// GatewayStatus, nor in the stats file, which has GatewayStatus's members.
  std::uint32_t other_state_writers = 0;
  SequenceTracker::Counts sequence;
  EgressCounters egress;
  /// Snapshots for the ROS 2 standard topics dropped because their publishing thread was a whole
  /// ring behind (Ros2StandardTopics::dropped()); 0 when those topics are off.
  std::uint64_t standard_dropped = 0;
  /// The longest time from a valid frame's arrival at the socket (kernel time stamp) to its
  /// publication, over the last status period and since start: how far the ingress runs behind.
  std::uint64_t ingress_delay_us = 0;
  std::uint64_t ingress_delay_max_us = 0;
  double rate_hz = 0;  ///< valid frames per second over the last status period
  bool link_up = false;
  std::string source;  ///< "HOST:PORT" of the last valid frame, empty before the first
};

/// One JSON object; counter names as in GatewayStatus.idl, `invalid` keyed by category name.
std::string to_json(const GatewayStats& stats);

/// One line for the periodic log.
std::string summary_line(const GatewayStats& stats);

/// "bad_crc=3 truncated=1": the non-zero counts of `counts`, in category order.
std::string format_invalid(const InvalidCounts& counts);

}  // namespace rsg::status
