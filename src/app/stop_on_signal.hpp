// SIGINT and SIGTERM as a stop request (and, for rsg_gateway, SIGUSR1 as a dump request and SIGHUP
// as a reload request) for every rsg executable. The signals are blocked in every thread
// (block_stop_signals() runs before DDS starts its threads) and taken synchronously by one thread
// of this object: no handler, no global flag, and no async-signal-unsafe code in a signal handler.
#pragma once

#include <pthread.h>

#include <csignal>
#include <functional>
#include <stop_token>
#include <thread>

namespace rsg::app {

class StopOnSignal {
 public:
  /// What a long-running service takes besides the stop signals (rsg_gateway).
  struct ServiceSignals {
    std::function<void()> on_dump;    ///< SIGUSR1
    std::function<void()> on_reload;  ///< SIGHUP
  };

  /// Blocks SIGINT and SIGTERM, and SIGUSR1 and SIGHUP `with_service_signals`, in the calling
  /// thread and in every thread it starts from then on. Call it first in main, before DDS starts its
  /// threads (Fast DDS 3 starts some when the XML profiles load): a thread that leaves the signal
  /// unblocked can take it, and discards it where it arrives ignored (a process started from a
  /// background job). Without it, SIGHUP keeps its default action (the tools are not services).
  /// A service also blocks SIGPIPE, which it never takes: a write to a closed connection then fails
  /// with EPIPE instead of ending the process, a death systemd would count as a clean exit.
  static void block_stop_signals(bool with_service_signals = false) {
    sigset_t signals = taken_signals(with_service_signals);
    if (with_service_signals) sigaddset(&signals, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  }

  /// Calls `on_stop` once, from this object's thread, when SIGINT or SIGTERM arrives.
  explicit StopOnSignal(std::function<void()> on_stop) : StopOnSignal(std::move(on_stop), false, {}) {}

  /// The same, and until then `service.on_dump` on every SIGUSR1 and `service.on_reload` on every
  /// SIGHUP (block_stop_signals(true) first).
  StopOnSignal(std::function<void()> on_stop, ServiceSignals service)
      : StopOnSignal(std::move(on_stop), true, std::move(service)) {}

 private:
  StopOnSignal(std::function<void()> on_stop, bool with_service_signals, ServiceSignals service)
      : thread_([on_stop = std::move(on_stop), with_service_signals,
                 service = std::move(service)](std::stop_token token) {
          ::pthread_setname_np(::pthread_self(), "rsg-signals");  // top -H, perf, tests find it by name
          const sigset_t signals = taken_signals(with_service_signals);
          const timespec poll{0, 100'000'000};  // to notice the stop request
          while (!token.stop_requested()) {
            const int signal = sigtimedwait(&signals, nullptr, &poll);
            if (signal == SIGUSR1) {
              if (service.on_dump) service.on_dump();
            } else if (signal == SIGHUP) {
              if (service.on_reload) service.on_reload();
            } else if (signal > 0) {
              on_stop();
              return;
            }
          }
        }) {}

  static sigset_t taken_signals(bool with_service_signals) {
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGINT);
    sigaddset(&signals, SIGTERM);
    if (with_service_signals) {
      sigaddset(&signals, SIGUSR1);
      sigaddset(&signals, SIGHUP);
    }
    return signals;
  }

  std::jthread thread_;
};

}  // namespace rsg::app
