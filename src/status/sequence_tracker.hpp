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
//     - time earlier by more: a restart of the robot, or a frame of another stream (see below).
//   * Ahead by d: the d-1 frames skipped are counted lost (a gap longer than 16 frames cannot be
//     told from a shorter one: packet numbers only count modulo 16; a pause where the robot sends
//     nothing while its time runs on is not a loss).
//   * Behind: a bit window of the last 64 positions says whether that frame arrived already. If
//     it did, the frame is a duplicate; if not, it arrives late: reordered, and no longer lost.
//   * Restart: counted, and the frame starts a fresh sequence (nothing lost across a restart).
//
// With `time`, the tracker also says which frames continue the stream, so that only those are
// published (observe() returns the verdict). The robot's `time` increases strictly (docs/protocol.md),
// and a controller that reads the newest sample must never be taken back in time, so a frame
// whose time is earlier than that of the newest frame is counted `out_of_sequence` and not
// published: a late frame (still counted reordered or duplicated as above), a replayed one, or
// one interleaved by a forger. So is a frame whose time jumps further ahead than the arrival
// clock has run since the newest frame, plus a jitter allowance (`silence`): the robot's clock
// and the host's run at the same rate, a forged frame from the future need not.
//
// A restart is believed only when nothing else explains the jump: a frame of another sequence
// continues the one before it (later time, the next packet numbers, both clocks in step), and the
// stream followed so far has been silent for `silence` (what takes the link down, link_monitor.hpp).
// The frame of the new sequence before the one that confirms it is held (observe() says kHeld) and
// published first once the restart is believed, so a robot that reboots after a pause loses no
// frame. A replayed or forged frame interleaved with the robot's stream therefore never counts as
// a restart, nor shifts the packet numbers the stream's losses are counted from; only a sender
// that outlasts the robot's own silence can start a new sequence. A robot that starts a new
// sequence without a pause has its first frames counted out_of_sequence until its old stream has
// been silent for that long. Frames without `time` cannot be told apart this way: every one is
// published and only the packet-number rules above apply. So only frames with `time` are surely
// the stream's: in a stream where some frames carry none, the silence is that of the frames with
// time, and a frame without time that goes on from the held frame's packet number confirms the
// restart as well.
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

#include <chrono>
#include <cstdint>
#include <optional>

namespace rsg::status {

class SequenceTracker {
 public:
  struct Counts {
    std::uint64_t lost = 0;
    std::uint64_t duplicated = 0;
    std::uint64_t reordered = 0;
    std::uint64_t restarts = 0;
    /// Valid frames not published: their time went back, or jumped ahead beyond the arrival clock.
    std::uint64_t out_of_sequence = 0;

    friend bool operator==(const Counts&, const Counts&) = default;
  };

  /// When a frame arrived (the gateway's steady clock).
  using Arrival = std::chrono::steady_clock::time_point;
  static constexpr std::chrono::milliseconds kDefaultSilence{10};

  /// Whether a frame continues the stream (publish it) or not (drop it), or may be the first of a
  /// restarted sequence (keep it: if the next frame confirms the restart, publish it first).
  enum class Verdict : std::uint8_t { kInSequence, kOutOfSequence, kHeld };
  /// Frames of another sequence that confirm it, the first one included.
  static constexpr unsigned kConfirmFrames = 2;

  /// `restart_threshold_ms`: how far `time` must go backwards to be a restart, not a late frame.
  /// `silence`: how long the stream must have been silent before a frame of another sequence is
  /// believed to be the robot's restart; also how far `time` may run ahead of the arrival clock.
  explicit SequenceTracker(std::uint64_t restart_threshold_ms = 100,
                           std::chrono::steady_clock::duration silence = kDefaultSilence);

  /// Accounts one valid frame that arrived at `arrival`; `time_ms` is its `time` field when the
  /// frame carries one.
  Verdict observe(std::uint8_t packet_number, std::optional<std::uint64_t> time_ms, Arrival arrival) noexcept;

  /// Accounts one datagram the decoder rejected: it arrived, so the gap it leaves is not a loss.
  void on_invalid() noexcept {
    ++invalid_credits_;
    frames_since_invalid_ = 0;
  }

  /// After a kInSequence verdict: the frame held just before is published first (the restart it
  /// began is believed). A held frame counts out_of_sequence until then.
  bool releases_held() const { return releases_held_; }

  const Counts& counts() const { return counts_; }

 private:
  void start(std::uint8_t packet_number, std::optional<std::uint64_t> time_ms, Arrival arrival) noexcept;
  void advance(unsigned distance, std::uint8_t packet_number, std::optional<std::uint64_t> time_ms,
               Arrival arrival) noexcept;
  Verdict another_sequence(std::uint8_t packet_number, std::uint64_t time_ms, Arrival arrival,
                           bool was_holding) noexcept;
  Verdict restart(unsigned ahead, std::uint8_t packet_number, std::optional<std::uint64_t> time_ms,
                  Arrival arrival, bool release_held) noexcept;
  bool in_step(std::uint64_t from_ms, Arrival from_arrival, std::uint64_t to_ms,
               Arrival to_arrival) const noexcept;
  void arrive_late(unsigned age) noexcept;
  bool is_missing(unsigned age) const noexcept;

  std::uint64_t restart_threshold_ms_;
  std::chrono::steady_clock::duration silence_;
  Counts counts_;
  bool started_ = false;
  std::uint8_t newest_packet_number_ = 0;
  std::optional<std::uint64_t> newest_time_ms_;
  Arrival newest_arrival_{};       // of the newest frame in sequence: when the stream was last heard
  Arrival newest_time_arrival_{};  // of the newest frame in sequence that carried `time`
  // Bit a set: the frame `a` places behind the newest one has arrived (bit 0: the newest itself).
  std::uint64_t arrived_ = 0;
  // Bit a set: the missing frame `a` places behind the newest is covered by an invalid frame.
  std::uint64_t covered_ = 0;
  std::uint64_t invalid_credits_ = 0;  // invalid frames not yet matched with a gap
  unsigned frames_since_invalid_ = 0;

  // The newest frame of another sequence, while it may be a restart (`candidate_frames_` > 0).
  unsigned candidate_frames_ = 0;
  unsigned candidate_skipped_ = 0;  // packet numbers its frames skipped, up to the newest
  std::uint8_t candidate_packet_number_ = 0;
  std::uint64_t candidate_time_ms_ = 0;
  Arrival candidate_arrival_{};
  bool holding_ = false;  // the last frame observed was held
  bool releases_held_ = false;
};

}  // namespace rsg::status
