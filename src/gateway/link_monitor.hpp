// Whether the robot is streaming: the link is up from the first valid frame and goes down after
// `silent_periods` nominal frame periods without one, and never after less than kMinSilence:
// above ~1 kHz, ten periods are shorter than the scheduling hiccups of a loaded host, and the
// link flapped at 5 kHz.
//
// Silence produces no event, so the owner must call `poll()` by `deadline()` at the latest
// (typically as the timeout of its receive call), not only when frames arrive.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>

#include "gateway/clock.hpp"

namespace rsg::gateway {

class LinkMonitor {
 public:
  static constexpr unsigned kDefaultSilentPeriods = 10;
  static constexpr Clock::duration kMinSilence = std::chrono::milliseconds(10);

  explicit LinkMonitor(Clock::duration nominal_period, unsigned silent_periods = kDefaultSilentPeriods)
      : silence_limit_(std::max<Clock::duration>(nominal_period * silent_periods, kMinSilence)) {}

  /// A valid frame arrived. True when it brought the link up.
  bool on_frame(Clock::time_point now) {
    last_frame_ = now;
    if (up_) return false;
    up_ = true;
    return true;
  }

  /// True when the link has just gone down.
  bool poll(Clock::time_point now) {
    if (!up_ || now - last_frame_ < silence_limit_) return false;
    up_ = false;
    return true;
  }

  bool up() const { return up_; }
  /// How long without a valid frame takes the link down.
  Clock::duration silence_limit() const { return silence_limit_; }
  /// When `poll()` would next report the link down; far future while it is down.
  Clock::time_point deadline() const { return up_ ? last_frame_ + silence_limit_ : Clock::time_point::max(); }

 private:
  Clock::duration silence_limit_;
  Clock::time_point last_frame_{};
  bool up_ = false;
};

/// Frames per second between two readings of a running counter.
class RateMeter {
 public:
  /// The rate since the previous call (0 on the first call).
  double update(std::uint64_t count, Clock::time_point now) {
    const double seconds = std::chrono::duration<double>(now - last_time_).count();
    const double rate = started_ && seconds > 0 ? static_cast<double>(count - last_count_) / seconds : 0.0;
    started_ = true;
    last_count_ = count;
    last_time_ = now;
    return rate;
  }

 private:
  bool started_ = false;
  std::uint64_t last_count_ = 0;
  Clock::time_point last_time_{};
};

}  // namespace rsg::gateway
