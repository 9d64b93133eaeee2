// SIGINT and SIGTERM as a stop request (and SIGUSR1 as rsg_gateway's dump request) for every rsg
// executable. The signals are blocked in every thread (block_stop_signals() runs before DDS starts
// its threads) and taken synchronously by one thread of this object: no handler, no global flag, and
// no async-signal-unsafe code in a signal handler.
#pragma once

#include <pthread.h>

#include <csignal>
#include <functional>
#include <stop_token>
#include <thread>

namespace rsg::app {

class StopOnSignal {
 public:
  /// Blocks SIGINT and SIGTERM, and SIGUSR1 `with_dump`, in the calling thread and in every thread
  /// it starts from then on. Call it first in main, before DDS starts its threads (Fast DDS 3 starts
  /// some when the XML profiles load): a thread that leaves the signal unblocked can take it, and
  /// discards it where it arrives ignored (a process started from a background job).
  static void block_stop_signals(bool with_dump = false) {
    const sigset_t signals = taken_signals(with_dump);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  }

  /// Calls `on_stop` once, from this object's thread, when SIGINT or SIGTERM arrives; and `on_dump`
  /// (when given: block_stop_signals(true) first) on every SIGUSR1 until then.
  explicit StopOnSignal(std::function<void()> on_stop, std::function<void()> on_dump = {})
      : thread_([on_stop = std::move(on_stop), on_dump = std::move(on_dump)](std::stop_token token) {
          const sigset_t signals = taken_signals(static_cast<bool>(on_dump));
          const timespec poll{0, 100'000'000};  // to notice the stop request
          while (!token.stop_requested()) {
            const int signal = sigtimedwait(&signals, nullptr, &poll);
            if (signal == SIGUSR1) {
              on_dump();
            } else if (signal > 0) {
              on_stop();
              return;
            }
          }
        }) {}

 private:
  static sigset_t taken_signals(bool with_dump) {
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGINT);
    sigaddset(&signals, SIGTERM);
    if (with_dump) sigaddset(&signals, SIGUSR1);
    return signals;
  }

  std::jthread thread_;
};

}  // namespace rsg::app
