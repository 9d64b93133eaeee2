// What every rsg participant does in front of Fast DDS's network transports so that no datagram
// and no peer can abort it, spin it or grow it without bound (docs/fastdds-versions.md, "What no
// packet can do"), and its counts.
//
//   rsg::dds::Participant participant(domain, "rsg_participant");
//   participant.rtps_guard().statistics_misplaced.load();
//   participant.rtps_guard().screened(rsg::dds::RtpsScreenReason::kDataFrag);
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace rsg::dds {

/// Why the RTPS screen refused a received RTPS message, or the rest of it from one submessage on
/// (RTPS 2.5, 8.3.4.1: a receiver ignores the rest of a message after an invalid submessage). Each
/// is a check that fixed Fast DDS releases make and the versions rsg links may not
/// (docs/fastdds-versions.md lists the published flaw behind each).
enum class RtpsScreenReason : std::uint8_t {
  kNotRtps,            ///< shorter than an RTPS header, not "RTPS", or RTPS major version not 2
  kSubmessageLength,   ///< a submessage header or length that runs past the message
  kData,               ///< DATA: offsets, flags or sequence number inconsistent
  kDataFrag,           ///< DATA_FRAG: fragment numbers, sizes or bytes present inconsistent
  kFragmentedBuiltin,  ///< DATA_FRAG to or from a built-in (discovery, security) endpoint
  kSampleTooLarge,     ///< a fragmented sample larger than kMaxFragmentedSampleBytes
  kGap,                ///< GAP: inverted or oversized range, bitmap past the submessage
  kHeartbeat,          ///< HEARTBEAT / HEARTBEAT_FRAG: sequence numbers inconsistent
  kAckNack,            ///< ACKNACK: bitmap larger than 256 bits or past the submessage
  kNackFrag,           ///< NACK_FRAG: the same
  kInfo,               ///< INFO_TS / INFO_SRC / INFO_DST / INFO_REPLY shorter than their content
  kInlineQos,          ///< an inline QoS parameter list not well-formed
  kParameterList,      ///< a built-in sample's parameter list not well-formed or encapsulated
  kParameterValue,     ///< a parameter whose count, string or duration disagrees with its length
  kTooManyLocators,    ///< an announcement with more locators than kMaxLocatorsPerAnnouncement
  kBuiltinPayload,     ///< a built-in sample that is not a parameter list, not well-formed
  kUnknownSubmessage,  ///< a submessage id RTPS 2.5 and DDS Security do not define (below 0x80)
  kAnnouncedTooMuch,   ///< user data, partitions or properties over what an rsg participant keeps
};
inline constexpr std::size_t kRtpsScreenReasons = 18;

/// The label of each reason on /metrics (`rsg_dds_screen_dropped_total{reason="..."}`).
constexpr std::string_view to_string(RtpsScreenReason reason) noexcept {
  // clang-format off
  constexpr std::array<std::string_view, kRtpsScreenReasons> names{
      "not_rtps", "submessage_length", "data", "data_frag", "fragmented_builtin", "sample_too_large",
      "gap", "heartbeat", "acknack", "nack_frag", "info", "inline_qos", "param_list", "param_value",
      "locators", "builtin_payload", "unknown_submessage", "announced_too_much"};
  // clang-format on
  return names[static_cast<std::size_t>(reason)];
}
static_assert(to_string(RtpsScreenReason::kAnnouncedTooMuch) == "announced_too_much",
              "one name per reason, in the enum's order");

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
  /// Participant announcements dropped: one participant more on probation (never heard from but
  /// through its announcements) than one source, or all sources, may have (docs/security.md).
  std::atomic<std::uint64_t> announcements_refused{0};
  /// Announcements of participants on probation handed on with their lease cut to 30 s.
  std::atomic<std::uint64_t> leases_shortened{0};
  /// Received messages refused, whole or from one submessage on, by reason.
  std::array<std::atomic<std::uint64_t>, kRtpsScreenReasons> screened_out{};

  /// How many messages the screen refused for `reason` so far.
  std::uint64_t screened(RtpsScreenReason reason) const noexcept {
    return screened_out[static_cast<std::size_t>(reason)].load(std::memory_order_relaxed);
  }
};

}  // namespace rsg::dds
