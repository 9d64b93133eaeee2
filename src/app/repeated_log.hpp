// The one way rsg paces a log line that an outsider (or a misconfigured robot) can make repeat:
// a link flap, a reload, a signal, a datagram from outside allow-from, an invalid frame, a limit
// that bit. The first line is logged at once; after it, events are only counted, and one line a
// minute says how many came since the line before. A flood of events therefore costs at most one
// line a minute per kind, while a single event (the first after a quiet minute) is never delayed.
//
// It counts in two integers and a time: nothing is allocated, so it may sit on the per-frame path
// (tests/app/repeated_log_test.cpp counts the allocations). One thread uses an instance.
#pragma once

#include <chrono>
#include <cstdint>

namespace rsg::app {

class RepeatedLog {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr Clock::duration kInterval = std::chrono::minutes(1);

  RepeatedLog() noexcept = default;
  explicit RepeatedLog(Clock::duration interval) noexcept : interval_(interval) {}

  /// Counts `n` events at `now` (0: none, only asks whether held ones are due) and returns how
  /// many the line to log now stands for -- these and every one held since the last line -- or 0
  /// when no line is due: the events are held until the interval since the last line has passed.
  /// The first events ever, and the first after a quiet interval, are due at once.
  std::uint64_t take(Clock::time_point now, std::uint64_t n = 1) noexcept {
    held_ += n;
    total_ += n;
    if (held_ == 0) return 0;
    if (logged_once_ && now - last_ < interval_) return 0;
    logged_once_ = true;
    last_ = now;
    const std::uint64_t due = held_;
    held_ = 0;
    return due;
  }

  /// Events counted since start, logged or held.
  std::uint64_t total() const noexcept { return total_; }
  /// Events counted and not yet in a line.
  std::uint64_t held() const noexcept { return held_; }

 private:
  Clock::duration interval_ = kInterval;
  Clock::time_point last_{};
  std::uint64_t held_ = 0;
  std::uint64_t total_ = 0;
  bool logged_once_ = false;
};

}  // namespace rsg::app
