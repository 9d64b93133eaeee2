// Lost, duplicated and reordered frames and robot restarts, from the 4-bit packet number.
//
// The packet number alone wraps every 16 frames, so on its own it can only place a frame within
// 8 frames ahead of or 7 behind the newest one. When frames carry the robot's `time` (ms since
// robot start, strictly increasing), time decides the direction instead and recognises restarts:
//
//   * Every frame gets an unwrapped sequence number relative to the newest frame seen so far.
//     - without time: packet-number distance d = (pn - newest_pn) mod 16; d = 1..8 is ahead,
//       d = 9..15 is 16-d behind, d = 0 is the newest frame again;
//     - with time (this frame and the newest both carry it): time later than the newest is ahead
//       by d (d = 0 meaning a full wrap, 16); the same time is the newest frame again; earlier
//       time is behind by (newest_pn - pn) mod 16 (0 meaning 16); earlier by more than
//       `restart_threshold_ms` is a robot restart.
//   * Ahead by d: the d-1 frames skipped are counted lost (a gap longer than 16 frames cannot be
//     told from a shorter one: packet numbers only count modulo 16).
//   * Behind: a bit window of the last 64 sequence numbers says whether that frame arrived
//     already. If it did, the frame is a duplicate; if not, it arrives late: reordered, and no
//     longer lost.
//   * Restart: counted, and the frame starts a fresh sequence (nothing lost across a restart).
//
// "Lost" therefore means "never arrived valid": frames dropped by the network and frames the
// decoder rejected look the same here.
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

  const Counts& counts() const { return counts_; }

 private:
  void start(std::uint8_t packet_number, std::optional<std::uint64_t> time_ms) noexcept;
  void advance(unsigned distance, std::uint8_t packet_number, std::optional<std::uint64_t> time_ms) noexcept;
  void arrive_late(unsigned age) noexcept;

  std::uint64_t restart_threshold_ms_;
  Counts counts_;
  bool started_ = false;
  std::uint8_t newest_packet_number_ = 0;
  std::optional<std::uint64_t> newest_time_ms_;
  // Bit a set: the frame `a` places behind the newest one has arrived (bit 0: the newest itself).
  std::uint64_t arrived_ = 0;
};

}  // namespace rsg::gateway
