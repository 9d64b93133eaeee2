// The frames every scenario of rsg_bench_e2e sends: full 2137-byte SEND_BUF frames that carry
// their own index and send time, so that a receiver in another process can compute the latency
// from one clock and tell lost frames from late ones.
//
// The stamp lives in `elbow_d`, a field of exactly two doubles: [0] = frame index, [1] = send
// time in ns of CLOCK_MONOTONIC (std::chrono::steady_clock on Linux), which every process of the
// host shares. The gateway copies field values without looking at them, so the stamp reaches the
// DDS sample unchanged; a double holds both exactly for 2^53 frames / ns (104 days of uptime).
// `time` counts frames like a robot's millisecond clock, so the gateway's sequence tracker sees
// an ordinary stream.
#pragma once

#include <RobotState.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <span>

#include "rsg/wire/frame.hpp"
#include "rsg/wire/state_values.hpp"

namespace rsg::bench {

using Clock = std::chrono::steady_clock;
static_assert(Clock::is_steady);

/// Now on the host-wide monotonic clock, in ns.
inline std::int64_t monotonic_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

struct Stamp {
  std::uint64_t index = 0;
  std::int64_t sent_ns = 0;
};

class StampedFrames {
 public:
  /// Every field selected, with fixed plausible values; only the stamp and the counters change.
  StampedFrames();

  /// Makes the current frame number `index`, stamped with the time now. The stamp is taken
  /// before the frame is encoded or copied into a sample, so the receiver's latency includes
  /// that work, as it would include a robot's.
  void stamp_now(std::uint64_t index);

  /// The current frame, encoded: what a robot would send (and the UDP baseline's datagram). The
  /// span refers to a buffer that the next call reuses.
  std::span<const std::uint8_t> encode();

  /// The current frame as the plain DDS baseline writes it: the same values in a sample.
  void fill(RobotState& sample) const;

 private:
  wire::StateValues values_;
  std::array<std::uint8_t, wire::kMaxFrameBytes> frame_{};
};

/// The stamp of a frame that carries one.
std::optional<Stamp> read_stamp(const wire::FrameView& frame);
Stamp read_stamp(const RobotState& sample);

}  // namespace rsg::bench
