// What the gateway's main loop tells whoever supervises it (rsg_gateway: systemd, through
// ServiceNotifier). Every call comes from the loop's own thread, so a loop that stops turning
// stops calling: that is what a watchdog needs.
#pragma once

#include "gateway/clock.hpp"
#include "status/stats.hpp"

namespace rsg::gateway {

class LoopObserver {
 public:
  virtual ~LoopObserver() = default;
  /// The socket is bound, the DDS entities exist, the loop is about to take its first frame.
  virtual void started(const status::GatewayStats& stats, bool has_ingress) = 0;
  /// One turn of the loop (at least every 100 ms while it runs).
  virtual void turned(Clock::time_point now) = 0;
  /// Once per status period, with the counters just published.
  virtual void status(const status::GatewayStats& stats, bool has_ingress) = 0;
  /// The loop has ended; the gateway is shutting down.
  virtual void stopping() = 0;
};

}  // namespace rsg::gateway
