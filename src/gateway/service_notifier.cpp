#include "gateway/service_notifier.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>

#include <cstdlib>
#include <cstring>

namespace rsg::gateway {

ServiceNotifier::ServiceNotifier() {
  const char* socket = std::getenv("NOTIFY_SOCKET");
  active_ = socket != nullptr && socket[0] != '\0';
  std::uint64_t usec = 0;
  // > 0: the watchdog is on for this process (WATCHDOG_PID, when set, is ours).
  if (active_ && ::sd_watchdog_enabled(0, &usec) > 0 && usec > 0)
    watchdog_ = std::chrono::duration_cast<Clock::duration>(std::chrono::microseconds(usec));
}

void ServiceNotifier::notify(const std::string& state) {
  if (!active_) return;
  const int result = ::sd_notify(0, state.c_str());
  if (result < 0 && !std::exchange(failed_, true))
    spdlog::warn("cannot notify the service manager ({}): {}", std::getenv("NOTIFY_SOCKET"),
                 std::strerror(-result));
}

void ServiceNotifier::ready(std::string_view status) { notify(fmt::format("READY=1\nSTATUS={}", status)); }

void ServiceNotifier::set_status(std::string_view line) { notify(fmt::format("STATUS={}", line)); }

void ServiceNotifier::watchdog(Clock::time_point now) {
  if (!watchdog_) return;
  if (last_ping_ && now - *last_ping_ < *watchdog_ / 2) return;
  last_ping_ = now;
  notify("WATCHDOG=1");
}

void ServiceNotifier::status(const status::GatewayStats& stats, bool has_ingress) {
  status::IngressCounters period;
  period.rejected_source = stats.ingress.rejected_source - last_.rejected_source;
  for (std::size_t i = 0; i < period.invalid.size(); ++i)
    period.invalid[i] = stats.ingress.invalid[i] - last_.invalid[i];
  last_ = stats.ingress;
  set_status(service_status_line(stats, has_ingress, period));
}

void ServiceNotifier::stopping() { notify("STOPPING=1"); }

std::string service_status_line(const status::GatewayStats& stats, bool has_ingress,
                                const status::IngressCounters& period) {
  const std::uint32_t readers = stats.state_readers + stats.standard_readers;
  std::string line;
  if (has_ingress) {
    line = stats.link_up ? fmt::format("link up from {} at {:.1f} Hz", stats.source, stats.rate_hz)
                         : std::string("link down");
    // What the log says once a second, in the line `systemctl status` shows: why the link is down.
    std::string causes;
    if (period.rejected_source > 0)
      causes = fmt::format("ignoring {} datagrams/s from outside --allow-from", period.rejected_source);
    if (const std::uint64_t invalid = period.invalid_total(); invalid > 0)
      causes += fmt::format("{}rejecting {} invalid frames/s ({})", causes.empty() ? "" : ", ", invalid,
                            status::format_invalid(period.invalid));
    if (!causes.empty()) line += (stats.link_up ? ", " : ": ") + causes;
  } else {
    line = fmt::format("egress only, {} sent", stats.egress.frames_sent);
  }
  line += fmt::format(", {} reader{}", readers, readers == 1 ? "" : "s");
  // First, where `systemctl status` cuts a long line last: readers get two robots' samples mixed.
  if (stats.other_state_writers > 0)
    line = fmt::format("ROBOTS MIXED: {} other writer{} of the state topic in this partition; ",
                       stats.other_state_writers, stats.other_state_writers == 1 ? "" : "s") +
           line;
  if (stats.egress_writers > 0)
    line += fmt::format(", {} egress writer{}", stats.egress_writers, stats.egress_writers == 1 ? "" : "s");
  return line;
}

}  // namespace rsg::gateway
