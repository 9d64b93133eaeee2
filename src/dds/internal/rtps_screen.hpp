// INTERNAL, not part of rsg's API and not installed (src/dds/internal/).
//
// What of a received RTPS datagram Fast DDS may read. Fast DDS 2.9 to 3.1 as Debian builds them
// (assertions on, statistics compiled in) abort on a statistics submessage that is not the last of
// its message (`read_statistics_submessage`), and the lost-traffic statistics assert on sequence
// numbers a peer chooses; release builds read the same bytes with undefined or wrong results.
// rsg reads no statistics, so the datagram is handed on without its statistics submessage and
// everything after it (docs/fastdds-versions.md, "What no packet can do").
//
// The walk is Fast DDS's own (MessageReceiver::notify_network_statistics, readSubmessageHeader):
// the same vendor check, the same "length 0 means last" rule, the same 4-byte alignment, so the
// submessages before the cut reach Fast DDS exactly as sent and it never meets one.
// DDS-free on purpose: fuzzed alone (tests/fuzz/fuzz_rtps_screen.cpp).
#pragma once

#include <cstdint>

namespace rsg::dds::internal {

/// The eProsima vendor-specific submessage that carries network statistics.
inline constexpr std::uint8_t kStatisticsSubmessageId = 0x80;

struct RtpsScreen {
  enum class Cut : std::uint8_t {
    kNone,       ///< handed on whole
    kTrailing,   ///< a statistics submessage where Fast DDS puts it, last, cut off: every message
                 ///< of a Fast DDS peer built with statistics has one
    kMisplaced,  ///< a statistics submessage anywhere else, or of another length, cut off with what
                 ///< follows: what aborts Fast DDS; no Fast DDS sends it
  };
  std::uint32_t forward_bytes;  ///< how many leading bytes Fast DDS may read
  Cut cut;
};

/// Never fails: a datagram that is not RTPS, not from an eProsima participant, or malformed before
/// any statistics submessage is handed on whole (Fast DDS drops what it cannot parse itself).
RtpsScreen screen_rtps_datagram(const std::uint8_t* datagram, std::uint32_t size) noexcept;

}  // namespace rsg::dds::internal
