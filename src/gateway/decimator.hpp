// Which frames of a stream a slower output takes: every Nth one, or at most R a second.
//
// Shared by --rate-topic and the ROS 2 standard topics (--joint-states, --tf, --external-wrench).
// A rate is paced by the robot's `time` when frames carry it (so a loaded host that delivers a
// burst late still gets the robot's spacing), else by arrival. No allocation, no lock: it runs on
// the ingress thread.
#pragma once

#include <chrono>
#include <cstdint>

namespace rsg::gateway {

/// A decimation as configured: `every` > 0 takes every Nth frame, else `period` > 0 is the least
/// spacing between two frames taken.
struct Decimation {
  std::uint32_t every = 0;
  std::chrono::nanoseconds period{};
};

class Decimator {
 public:
  explicit Decimator(Decimation decimation) : decimation_(decimation) {}

  /// True when the frame at time `t` (the robot's, else arrival) is taken. Called once per frame
  /// the output could take, in arrival order.
  bool due(std::chrono::nanoseconds t) {
    if (decimation_.every > 0) {
      const bool take = count_ == 0;
      count_ = (count_ + 1) % decimation_.every;
      return take;
    }
    const auto period = decimation_.period;
    // A restarted robot (time going back) or a stall restarts the schedule instead of catching up.
    if (scheduled_ && t >= due_ && t < due_ + period) {
      due_ += period;
    } else if (!scheduled_ || t >= due_ || t + period < due_) {
      due_ = t + period;
      scheduled_ = true;
    } else {
      return false;  // not due yet
    }
    return true;
  }

 private:
  Decimation decimation_;
  std::uint32_t count_ = 0;
  // A flag rather than std::optional: GCC 12 warns (maybe-uninitialized) on the inlined optional.
  bool scheduled_ = false;  // false: the next frame is due
  std::chrono::nanoseconds due_{};
};

}  // namespace rsg::gateway
