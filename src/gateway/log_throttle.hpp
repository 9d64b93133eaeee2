// Rate limit for log lines about per-frame events: the hot path counts, and a summary is logged
// at most once per interval, so a flood of bad frames cannot turn into a flood of log lines.
#pragma once

#include <string>

#include "gateway/clock.hpp"

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

/// When the gateway logs its summary line: at most every `busy` while the line changes (frames
/// flow, counters move), and every `idle` while it does not, so that an idle gateway's log stays
/// quiet (a line an hour, not one every 10 s) yet still shows it is alive.
class SummaryPacer {
 public:
  static constexpr Clock::duration kBusy = std::chrono::seconds(10);
  static constexpr Clock::duration kIdle = std::chrono::hours(1);

  explicit SummaryPacer(Clock::time_point start, Clock::duration busy = kBusy, Clock::duration idle = kIdle)
      : busy_(busy), idle_(idle), next_(start + busy), idle_due_(start + idle) {}

  /// When a summary may be due: ask no earlier (saves building the line every status period).
  bool may_log(Clock::time_point now) const { return now >= next_; }

  /// True when `line`, the summary at `now`, is to be logged: it differs from the last one logged
  /// (the first one always does), or the last one was logged `idle` ago.
  bool due(const std::string& line, Clock::time_point now) {
    if (now < next_) return false;
    next_ = now + busy_;
    if (line == last_ && now < idle_due_) return false;
    last_ = line;
    idle_due_ = now + idle_;
    return true;
  }

 private:
  Clock::duration busy_;
  Clock::duration idle_;
  Clock::time_point next_;
  Clock::time_point idle_due_;
  std::string last_;
};

}  // namespace rsg::gateway
