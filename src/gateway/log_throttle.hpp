// The pacing of the gateway's summary line. Lines about events an outsider can repeat go through
// app::RepeatedLog (src/app/repeated_log.hpp) instead: the first at once, then a count a minute.
#pragma once

#include <string>

#include "gateway/clock.hpp"

namespace rsg::gateway {

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
