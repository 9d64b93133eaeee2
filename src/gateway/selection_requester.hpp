// When to ask the robot (again) for the selection the gateway wants, and what to say about it.
//
// The request goes out at start-up and again whenever frames arrive with another selection,
// because a robot that restarted, or one that missed the request (UDP), streams its default.
// Repeats are at most one per `min_interval`, since the frames already in flight still carry the
// old selection. A robot that has not answered kTriesBeforeWarning requests (its frames still carry
// another selection) is not listening where they go: the gateway says so once, with the numbers, and
// from then on asks only every kSlowInterval, until frames carry the wanted selection again.
#pragma once

#include <spdlog/spdlog.h>

#include <string>

#include "gateway/clock.hpp"
#include "rsg/wire/selection.hpp"

namespace rsg::gateway {

class SelectionRequester {
 public:
  static constexpr unsigned kTriesBeforeWarning = 3;
  static constexpr Clock::duration kSlowInterval = std::chrono::seconds(10);

  explicit SelectionRequester(const wire::Selection& wanted,
                              Clock::duration min_interval = std::chrono::seconds(1))
      : wanted_(wanted), min_interval_(min_interval) {}

  const wire::Selection& wanted() const { return wanted_; }

  /// True for the start-up request (the first call). Records the request as sent.
  bool start_up_due(Clock::time_point now) { return record_if(!requested_once_, now); }

  /// True when a frame carrying `seen` should trigger a new request. Records the request as sent.
  bool due(const wire::Selection& seen, Clock::time_point now) {
    if (seen == wanted_) {
      if (unanswered_ > kTriesBeforeWarning)
        spdlog::info("the robot streams the requested selection group_select=0x{:02x} now, after {} requests",
                     wanted_.group_select, unanswered_);
      unanswered_ = 0;
      return false;
    }
    seen_ = seen;
    const Clock::duration interval = unanswered_ > kTriesBeforeWarning ? kSlowInterval : min_interval_;
    return record_if(!requested_once_ || now - last_request_ >= interval, now);
  }

  /// Requests sent since frames last carried the wanted selection.
  unsigned unanswered() const { return unanswered_; }

  /// Logs the request just sent to `robot`: one line for each of the first kTriesBeforeWarning, then
  /// one warning that the robot does not answer (`source`: where its frames come from, "" before
  /// the first), then nothing. Rare (at most once a second), so it may log.
  void log_sent(const std::string& robot, const std::string& source) const {
    if (unanswered_ <= kTriesBeforeWarning) {
      spdlog::info("asked {} for selection group_select=0x{:02x}", robot, wanted_.group_select);
    } else if (unanswered_ == kTriesBeforeWarning + 1) {
      spdlog::warn(
          "{} selection requests to {} went unanswered: the frames{} still carry group_select=0x{:02x}, not "
          "0x{:02x}. A robot takes requests on the port it streams from unless --robot names another: is "
          "that where it listens? Asking every {} s from now on",
          kTriesBeforeWarning, robot, source.empty() ? std::string() : " from " + source, seen_.group_select,
          wanted_.group_select, std::chrono::duration_cast<std::chrono::seconds>(kSlowInterval).count());
    }
  }

 private:
  bool record_if(bool condition, Clock::time_point now) {
    if (condition) {
      requested_once_ = true;
      last_request_ = now;
      ++unanswered_;
    }
    return condition;
  }

  wire::Selection wanted_;
  wire::Selection seen_;
  Clock::duration min_interval_;
  Clock::time_point last_request_{};
  bool requested_once_ = false;
  unsigned unanswered_ = 0;
};

}  // namespace rsg::gateway
