// What the simulator put on the wire, for the tests that check a receiver against it.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "rsg/wire/error.hpp"

namespace rsg::tools::sim {

/// Counts of datagrams and events. `sent` counts datagrams the kernel accepted (a duplicate twice),
/// `valid` those among them that decode; every other sent datagram is in `invalid` under the
/// category a decoder reports for it, so `sent == valid + sum(invalid)`.
struct SimReport {
  std::uint64_t sent = 0;
  std::uint64_t valid = 0;
  std::uint64_t dropped = 0;     ///< frames produced but deliberately not sent
  std::uint64_t duplicated = 0;  ///< frames sent a second time
  std::uint64_t reordered = 0;   ///< frames sent after a later frame
  std::array<std::uint64_t, wire::kErrorCategoryCount> invalid{};
  std::uint64_t restarts = 0;
  std::uint64_t pauses = 0;
  /// Times the host ran the simulator too late to keep its schedule, which then went on from there
  /// (udp_stream.cpp): silences of the link that no --pause-after asked for.
  std::uint64_t stalls = 0;
  std::uint64_t selection_requests = 0;  ///< valid requests applied
  std::uint64_t invalid_requests = 0;    ///< datagrams received that are no valid request
  std::uint64_t send_failures = 0;       ///< datagrams the kernel refused (not in `sent`)
  /// The longest time between two datagrams the kernel accepted, µs: how long the "robot" was
  /// really silent (its pauses, or a host too busy to run it on time).
  std::uint64_t longest_gap_us = 0;

  std::uint64_t& invalid_count(wire::ErrorCategory category) {
    return invalid[static_cast<std::size_t>(category) - 1];
  }
  std::uint64_t invalid_count(wire::ErrorCategory category) const {
    return invalid[static_cast<std::size_t>(category) - 1];
  }
  std::uint64_t invalid_total() const;

  /// One JSON object: the counters above by name, `invalid` an object keyed by category name.
  std::string to_json() const;
  /// One human-readable line for stderr.
  std::string summary() const;
};

}  // namespace rsg::tools::sim
