// Lost, duplicated and reordered frames and robot restarts, from the 4-bit packet number.
//
// The packet number alone wraps every 16 frames, so on its own it cannot tell a frame 15 ahead
// from one 1 behind. When frames carry the robot's `time` (ms since
// robot start, never decreasing), time decides the direction instead and recognises restarts:
//
//   * Every frame is placed relative to the newest frame seen so far. With d = (pn - newest_pn)
//     mod 16:
//     - without time, or with the same time as the newest frame (above 1 kHz frames share a
//       millisecond): d = 0 is the newest again; d = 9..15 is 16-d behind if that frame is
//       missing (a late frame filling its gap), otherwise every d is ahead. So a late frame is
//       recognised up to 7 behind, and a burst loss is never mistaken for old frames (it is
//       counted modulo 16), but a duplicate of an older frame reads as a jump ahead;
//     - time later than the newest: ahead by d (d = 0 meaning a full wrap, 16);
//     - time earlier by at most `restart_threshold_ms`: behind by (newest_pn - pn) mod 16
//       (0 meaning 16);
//     - time earlier by more: a robot restart.
//   * Ahead by d: the d-1 frames skipped are counted lost (a gap longer than 16 frames cannot be
//     told from a shorter one: packet numbers only count modulo 16; a pause where the robot sends
//     nothing while its time runs on is not a loss).
//   * Behind: a bit window of the last 64 positions says whether that frame arrived already. If
//     it did, the frame is a duplicate; if not, it arrives late: reordered, and no longer lost.
//   * Restart: counted, and the frame starts a fresh sequence (nothing lost across a restart).
//
// An invalid frame (rejected by the decoder, so its packet number cannot be trusted) is counted
// under its category, not as lost: `on_invalid()` notes it, and the next gaps ahead absorb one
// skipped position per invalid frame, as long as they come within 16 valid frames of it (an
// invalid datagram that fills no gap by then was not one of the robot's frames). A valid frame
// that arrives late into such a gap is reordered, and the invalid one is taken to have held another
// position of it (the simulator holds a frame back behind a corrupted one, and the gap shows only
// at the next valid frame). "Lost" therefore means "never arrived at all" (dropped by the network or the
// sender), as far as the packet numbers can tell.
#pragma once

#include <cstdint>
#include <optional>

namespace rsg::gateway {

class SequenceTracker {
 public:
  struct Counts {
    std::uint64_t lost = 0;
    std::uint64_t duplicated = 0;
    std::uint64_t reordered = 0;
    std::uint64_t restarts = 0;

    friend bool operator==(const Counts&, const Counts&) = default;
  };

  /// `restart_threshold_ms`: how far `time` must go backwards to be a restart, not a late frame.
  explicit SequenceTracker(std::uint64_t restart_threshold_ms = 100);

  /// Accounts one valid frame; `time_ms` is its `time` field when the frame carries one.
  void observe(std::uint8_t packet_number, std::optional<std::uint64_t> time_ms) noexcept;

  /// Accounts one datagram the decoder rejected: it arrived, so the gap it leaves is not a loss.
  void on_invalid() noexcept {
    ++invalid_credits_;
    frames_since_invalid_ = 0;
  }

  const Counts& counts() const { return counts_; }

 private:
  void start(std::uint8_t packet_number, std::optional<std::uint64_t> time_ms) noexcept;
  void advance(unsigned distance, std::uint8_t packet_number, std::optional<std::uint64_t> time_ms) noexcept;
  void arrive_late(unsigned age) noexcept;
  bool is_missing(unsigned age) const noexcept;

  std::uint64_t restart_threshold_ms_;
  Counts counts_;
  bool started_ = false;
  std::uint8_t newest_packet_number_ = 0;
  std::optional<std::uint64_t> newest_time_ms_;
  // Bit a set: the frame `a` places behind the newest one has arrived (bit 0: the newest itself).
  std::uint64_t arrived_ = 0;
  // Bit a set: the missing frame `a` places behind the newest is covered by an invalid frame.
  std::uint64_t covered_ = 0;
  std::uint64_t invalid_credits_ = 0;  // invalid frames not yet matched with a gap
  unsigned frames_since_invalid_ = 0;
};

}  // namespace rsg::gateway
