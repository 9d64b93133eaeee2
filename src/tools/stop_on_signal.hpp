// SIGINT and SIGTERM as a stop request for the command-line tools (rsg_echo, rsg_record,
// rsg_replay). The signals are blocked in every thread (block_stop_signals() runs before DDS starts
// its threads) and taken synchronously by one thread of this object, so no async-signal-unsafe code
// ever runs in a signal handler.
#pragma once

#include <pthread.h>

#include <csignal>
#include <functional>
#include <stop_token>
#include <thread>

namespace rsg::tools {

class StopOnSignal {
 public:
  static void block_stop_signals() {
    const sigset_t signals = stop_signals();
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  }

  /// Calls `on_stop` once, from this object's thread, when SIGINT or SIGTERM arrives.
  explicit StopOnSignal(std::function<void()> on_stop)
      : thread_([on_stop = std::move(on_stop)](std::stop_token token) {
          const sigset_t signals = stop_signals();
          const timespec poll{0, 100'000'000};  // to notice the stop request
          while (!token.stop_requested())
            if (sigtimedwait(&signals, nullptr, &poll) > 0) {
              on_stop();
              return;
            }
        }) {}

 private:
  static sigset_t stop_signals() {
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGINT);
    sigaddset(&signals, SIGTERM);
    return signals;
  }

  std::jthread thread_;
};

}  // namespace rsg::tools
