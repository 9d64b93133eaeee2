// Writes the flight recorder's dumps on a thread of its own, so that the ingress thread, which
// takes the snapshot, never waits on the disk; and bounds what they cost, so that whoever can
// flap the link or send SIGUSR1 cannot fill the disk: a minimum interval between dumps, and a cap
// on the number and bytes of rsg's own files in the folder, the oldest deleted first.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <thread>

#include "gateway/clock.hpp"
#include "gateway/flight_recorder.hpp"
#include "gateway/log_throttle.hpp"

namespace rsg::gateway {

/// Each dump is logged when its file is complete ("flight recorder (REASON): N datagrams in PATH")
/// or failed (an error line naming the file); failures are never thrown: the gateway goes on.
class DumpWriter {
 public:
  struct Options {
    std::filesystem::path dir;                             ///< where the dumps go (FlightRecorder's dir)
    std::chrono::duration<double> min_interval{};          ///< between two accepted dumps; 0: none
    std::size_t max_files = 100;                           ///< rsg_flight_*.pcap files kept in `dir`
    std::uintmax_t max_bytes = std::uintmax_t{500} << 20;  ///< their bytes
  };

  /// Dumps that may wait while one is written; a further one is refused (a disk this slow would
  /// only queue copies of the same seconds).
  static constexpr std::size_t kMaxPending = 2;

  /// What became of a request (`post`).
  enum class Posted { kQueued, kThrottled, kRefused };

  explicit DumpWriter(Options options);
  /// Writes what is still pending, then stops the thread.
  ~DumpWriter();
  DumpWriter(const DumpWriter&) = delete;
  DumpWriter& operator=(const DumpWriter&) = delete;

  /// When the last accepted dump is at least `min_interval` before `now` and fewer than
  /// kMaxPending dumps wait, calls `take` on the calling thread and queues the
  /// FlightRecorder::Snapshot it returns (taken for `reason`), then returns at once; otherwise
  /// counts the request as throttled or refused without calling `take`, so a request that is not
  /// dumped costs no copy. One thread posts (the ingress thread): room seen here cannot be used up
  /// before the snapshot is queued.
  template <class Take>
  Posted post(std::string reason, Clock::time_point now, Take&& take) {
    if (last_accepted_ && now - *last_accepted_ < options_.min_interval) {
      throttled_.fetch_add(1, std::memory_order_relaxed);
      return Posted::kThrottled;
    }
    if (!has_room()) return Posted::kRefused;
    last_accepted_ = now;
    enqueue({take(), std::move(reason)});
    return Posted::kQueued;
  }

  const Options& options() const { return options_; }

  /// Dumps written, failed, refused and throttled since start, and the files deleted to stay
  /// within the caps (any thread).
  std::uint64_t written() const { return written_.load(std::memory_order_relaxed); }
  std::uint64_t failed() const { return failed_.load(std::memory_order_relaxed); }
  std::uint64_t refused() const { return refused_.load(std::memory_order_relaxed); }
  std::uint64_t throttled() const { return throttled_.load(std::memory_order_relaxed); }
  std::uint64_t deleted() const { return deleted_.load(std::memory_order_relaxed); }

 private:
  struct Pending {
    FlightRecorder::Snapshot snapshot;
    std::string reason;
  };
  bool has_room();  // counts a refusal when not
  void enqueue(Pending pending);
  void run(const std::stop_token& stop);
  // Deletes rsg's oldest files in the folder until one of `bytes` more fits both caps.
  // @throws std::filesystem::filesystem_error when the folder cannot be listed or a file deleted.
  void make_room(std::uintmax_t bytes);

  Options options_;
  std::optional<Clock::time_point> last_accepted_;     // the posting thread's
  LogThrottle deleted_log_{std::chrono::minutes(10)};  // the writing thread's
  std::uint64_t deleted_logged_ = 0;                   // the writing thread's
  std::mutex mutex_;
  std::condition_variable_any posted_;
  std::deque<Pending> pending_;  // guarded by mutex_
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> failed_{0};
  std::atomic<std::uint64_t> refused_{0};
  std::atomic<std::uint64_t> throttled_{0};
  std::atomic<std::uint64_t> deleted_{0};
  std::jthread thread_;  // last: started once everything it uses exists
};

}  // namespace rsg::gateway
