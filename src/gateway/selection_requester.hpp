// When to ask the robot (again) for the selection the gateway wants.
//
// The request goes out at start-up and again whenever frames arrive with another selection,
// because a robot that restarted, or one that missed the request (UDP), streams its default.
// Repeats are at most one per `min_interval`, since the frames already in flight still carry the
// old selection.
#pragma once

#include "clock.hpp"
#include "rsg/wire/selection.hpp"

namespace rsg::gateway {

class SelectionRequester {
 public:
  explicit SelectionRequester(const wire::Selection& wanted,
                              Clock::duration min_interval = std::chrono::seconds(1))
      : wanted_(wanted), min_interval_(min_interval) {}

  const wire::Selection& wanted() const { return wanted_; }

  /// True for the start-up request (the first call). Records the request as sent.
  bool start_up_due(Clock::time_point now) { return record_if(!requested_once_, now); }

  /// True when a frame carrying `seen` should trigger a new request. Records the request as sent.
  bool due(const wire::Selection& seen, Clock::time_point now) {
    return record_if(seen != wanted_ && (!requested_once_ || now - last_request_ >= min_interval_), now);
  }

 private:
  bool record_if(bool condition, Clock::time_point now) {
    if (condition) {
      requested_once_ = true;
      last_request_ = now;
    }
    return condition;
  }

  wire::Selection wanted_;
  Clock::duration min_interval_;
  Clock::time_point last_request_{};
  bool requested_once_ = false;
};

}  // namespace rsg::gateway
