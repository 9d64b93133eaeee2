// Tells a supervising systemd how the gateway is (sd_notify(3), libsystemd): READY=1 once it is
// up, a one-line STATUS= every status period, WATCHDOG=1 from the loop that does the work, and
// STOPPING=1 on the way out. Without NOTIFY_SOCKET in the environment (not under a Type=notify
// unit) every call does nothing.
//
// The watchdog is pinged only by `watchdog(now)`, which the gateway's main loop calls on every
// turn: a loop that stops turning (ingress stuck, the process stopped) stops the pings, and
// systemd kills and restarts the service after WatchdogSec=. There is deliberately no timer thread.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <string_view>

#include "gateway/clock.hpp"
#include "gateway/loop_observer.hpp"
#include "status/stats.hpp"

namespace rsg::gateway {

/// The STATUS= line: "link up from HOST:PORT at 1000.0 Hz, 2 readers" (no line feed). With
/// `period`, the ingress counters' increase over the last status period (1 s), it names what keeps
/// a link down or what goes on beside it: "link down: ignoring 1000 datagrams/s from outside
/// --allow-from, 0 readers", "link down: rejecting 1000 invalid frames/s (bad_crc=1000), 0 readers".
std::string service_status_line(const status::GatewayStats& stats, bool has_ingress,
                                const status::IngressCounters& period = {});

class ServiceNotifier : public LoopObserver {
 public:
  /// Reads NOTIFY_SOCKET and the watchdog interval (WATCHDOG_USEC, WATCHDOG_PID) of this process.
  ServiceNotifier();

  // The gateway loop's events: READY=1 with the first STATUS=, STATUS= each period, WATCHDOG=1
  // from each turn (at most every half interval), STOPPING=1.
  void started(const status::GatewayStats& stats, bool has_ingress) override {
    last_ = stats.ingress;
    ready(service_status_line(stats, has_ingress));
  }
  void turned(Clock::time_point now) override { watchdog(now); }
  void status(const status::GatewayStats& stats, bool has_ingress) override;
  void stopping() override;

  /// True when a service manager listens (NOTIFY_SOCKET is set).
  bool active() const { return active_; }
  /// The interval systemd expects pings within; nothing when the watchdog is off.
  std::optional<Clock::duration> watchdog_interval() const { return watchdog_; }

  /// READY=1 with a first STATUS=: call once the socket is bound and the DDS entities exist.
  void ready(std::string_view status);
  /// STATUS=<line>.
  void set_status(std::string_view line);
  /// WATCHDOG=1 when half the watchdog interval has passed since the last ping (or at the first call).
  void watchdog(Clock::time_point now);

 private:
  void notify(const std::string& state);

  bool active_ = false;
  std::optional<Clock::duration> watchdog_;
  std::optional<Clock::time_point> last_ping_;
  bool failed_ = false;           // a notification failed: said once, not every time
  status::IngressCounters last_;  // as of the last status line: the next one tells what changed since
};

}  // namespace rsg::gateway
