// What every rsg participant does in front of Fast DDS's network transports so that no datagram
// and no peer can abort it (docs/fastdds-versions.md, "What no packet can do"), and its counts.
//
//   rsg::dds::Participant participant(domain, "rsg_participant");
//   participant.rtps_guard().statistics_misplaced.load();
#pragma once

#include <atomic>
#include <cstdint>

namespace rsg::dds {

/// Shared by the guarded transports of one participant; read from any thread.
struct RtpsGuardCounts {
  /// Received datagrams handed to Fast DDS without the eProsima statistics submessage that Fast DDS
  /// peers built with statistics put last in every message (normal traffic: rsg reads none).
  std::atomic<std::uint64_t> statistics_removed{0};
  /// Received datagrams with a statistics submessage anywhere else or of another length, handed on
  /// without it and what follows: what aborts Fast DDS builds with assertions; no Fast DDS sends it.
  std::atomic<std::uint64_t> statistics_misplaced{0};
  /// Destinations Fast DDS was about to send to without having opened a send channel for them (a
  /// reader that announces unicast and multicast locators): opened first, as Fast DDS 2.14.5 does.
  std::atomic<std::uint64_t> send_channels_opened{0};
  /// Such destinations for which no channel could be opened: not sent to.
  std::atomic<std::uint64_t> destinations_skipped{0};
};

}  // namespace rsg::dds
