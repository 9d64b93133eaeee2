// INTERNAL, not part of rsg's API and not installed (src/dds/internal/).
//
// What of a received RTPS datagram Fast DDS may read. Every rsg participant runs this on every
// datagram from the network before Fast DDS's parser sees it (rtps_guard.cpp), so that the flaws
// fixed in later Fast DDS releases cannot reach the one rsg links (docs/fastdds-versions.md, "What
// no packet can do"):
//  - each submessage is checked as the fixed Fast DDS checks it: its length against what is left,
//    the fixed part of each kind, sequence numbers and bitmaps, DATA_FRAG's fragment numbers, sizes
//    and bytes present; the inline QoS of every DATA / DATA_FRAG, and the serialized parameter list
//    of every sample to or from a built-in discovery endpoint (SPDP, SEDP, their secure variants),
//    parameter by parameter (counts against lengths, strings NUL-terminated, durations);
//  - the first submessage that fails, and everything after it, is not handed on (RTPS 2.5,
//    8.3.4.1: a receiver ignores the rest of a message after an invalid submessage), so the
//    datagram goes on shorter and is never copied; a message with nothing valid left is dropped;
//  - an eProsima statistics submessage is cut off with what follows: Fast DDS 2.9 to 3.1 as Debian
//    builds them abort on one that is not last, and rsg reads no statistics.
// The walk is Fast DDS's own (MessageReceiver::processCDRMsg and readSubmessageHeader): the same
// "length 0 means last" rule and the same 4-byte alignment, so that what is handed on reaches Fast
// DDS exactly as sent. Stateless, allocation-free, DDS-free on purpose: fuzzed alone
// (tests/fuzz/fuzz_rtps_screen.cpp) and against Wireshark's dissector (dds.rtps_screen_tshark).
#pragma once

#include <cstdint>

#include "rsg/dds/rtps_guard.hpp"

// The version of the Fast DDS this screen stands in front of (macros only: nothing of Fast DDS is
// called here).
#if __has_include(<fastdds/config.hpp>)
#include <fastdds/config.hpp>
#else
#include <fastrtps/config.h>
#endif

namespace rsg::dds::internal {

/// The eProsima vendor-specific submessage that carries network statistics.
inline constexpr std::uint8_t kStatisticsSubmessageId = 0x80;

/// The largest sample an rsg participant reassembles from fragments. A DATA_FRAG's sample size is
/// the sender's word, and Fast DDS reserves it at the first fragment: without a bound one datagram
/// per writer would reserve 4 GiB. rsg's own samples are a few kB (RobotState: 2.1 kB).
inline constexpr std::uint32_t kMaxFragmentedSampleBytes = 16u << 20;
/// The widest GAP (sequence numbers from gapStart to the bitmap's base) handed on. Fast DDS before
/// 2.14.6 / 3.2.4 walks every sequence number of a GAP, storing each: 2^32 of them spin a receive
/// thread and grow the process without end (CVE-2025-64438). A wider legitimate GAP (a late
/// joiner's first, from a writer with a long history) is not needed: the writer's HEARTBEAT tells
/// the reader the same (its first sequence number), one heartbeat period later.
inline constexpr std::int64_t kMaxGapRange = std::int64_t{1} << 20;
/// The same for the built-in discovery writers, whose sequence numbers count endpoint changes.
inline constexpr std::int64_t kMaxBuiltinGapRange = std::int64_t{1} << 16;
/// Locators of one kind (unicast, multicast, metatraffic unicast, ...) one announcement may carry.
/// Fast DDS keeps 4 unicast and 1 multicast per remote endpoint by default and sends a copy of
/// every sample to each: an announcement with more is an amplification attempt, not a host.
inline constexpr std::uint32_t kMaxLocatorsPerAnnouncement = 8;
/// The bytes of user data (and of group and topic data), of partition names and of properties (each
/// parameter's value) one announcement may carry. Fast DDS keeps every remote endpoint's announcement whole,
/// by default without a bound (120 writers with 60 kB of user data each held 7 MB of a plain participant);
/// given these as its data_limits it refuses a larger one, but keeps the refused sample in its discovery
/// reader's history for as long as the sender's participant lives (its listener removes a sample
/// only once it has read it: 2.9.1 to 3.6.1), so the screen refuses it first. ROS 2 announces about 80 bytes
/// of user data per endpoint (its type hash).
inline constexpr std::uint32_t kMaxAnnouncedUserDataBytes = 1024;
inline constexpr std::uint32_t kMaxAnnouncedPartitionBytes = 1024;
inline constexpr std::uint32_t kMaxAnnouncedPropertyBytes = 2048;

/// Whether a standard parameter of fixed size must have exactly its size, or at least it: Fast DDS
/// 2.9 refuses any other length, 2.14 and 3.x only a shorter one (ParameterSerializer,
/// QosPoliciesSerializer). A refused parameter leaves the whole announcement unread, and Fast DDS
/// keeps an unread discovery sample (kMaxAnnouncedUserDataBytes), so the screen refuses it first.
#if defined(FASTRTPS_VERSION_MAJOR) && FASTRTPS_VERSION_MAJOR == 2 && FASTRTPS_VERSION_MINOR < 14
inline constexpr bool kExactParameterLengths = true;
#else
inline constexpr bool kExactParameterLengths = false;
#endif

struct RtpsScreen {
  enum class Cut : std::uint8_t {
    kNone,       ///< handed on whole
    kTrailing,   ///< a statistics submessage where Fast DDS puts it, last, cut off: every message
                 ///< of a Fast DDS peer built with statistics has one
    kMisplaced,  ///< a statistics submessage anywhere else, or of another length, cut off with what
                 ///< follows: what aborts Fast DDS; no Fast DDS sends it
    kInvalid,    ///< a submessage that fails a check, cut off with what follows (`reason`)
  };
  std::uint32_t forward_bytes;  ///< how many leading bytes Fast DDS may read; the RTPS header
                                ///< (20) or less: nothing, the datagram is dropped
  Cut cut;
  RtpsScreenReason reason;  ///< with kInvalid: which check failed
};

/// Never fails, never reads outside [datagram, datagram + size), never allocates.
RtpsScreen screen_rtps_datagram(const std::uint8_t* datagram, std::uint32_t size) noexcept;

}  // namespace rsg::dds::internal
