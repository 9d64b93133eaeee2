// Rate limit for log lines about per-frame events: the hot path counts, and a summary is logged
// at most once per interval, so a flood of bad frames cannot turn into a flood of log lines.
#pragma once

#include "clock.hpp"

namespace rsg::gateway {

class LogThrottle {
 public:
  explicit LogThrottle(Clock::duration interval) : interval_(interval) {}

  /// True (and the interval restarts) when a line may be logged at `now`.
  bool allow(Clock::time_point now) {
    if (logged_once_ && now - last_ < interval_) return false;
    logged_once_ = true;
    last_ = now;
    return true;
  }

 private:
  Clock::duration interval_;
  Clock::time_point last_{};
  bool logged_once_ = false;
};

}  // namespace rsg::gateway
