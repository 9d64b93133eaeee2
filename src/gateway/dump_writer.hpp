// Writes the flight recorder's dumps on a thread of its own, so that the ingress thread, which
// takes the snapshot, never waits on the disk.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <stop_token>
#include <string>
#include <thread>

#include "flight_recorder.hpp"

namespace rsg::gateway {

/// Each dump is logged when its file is complete ("flight recorder (REASON): N datagrams in PATH")
/// or failed (an error line naming the file); failures are never thrown: the gateway goes on.
class DumpWriter {
 public:
  /// Dumps that may wait while one is written; a further one is refused (a disk this slow would
  /// only queue copies of the same seconds).
  static constexpr std::size_t kMaxPending = 2;

  DumpWriter();
  /// Writes what is still pending, then stops the thread.
  ~DumpWriter();
  DumpWriter(const DumpWriter&) = delete;
  DumpWriter& operator=(const DumpWriter&) = delete;

  /// When fewer than kMaxPending dumps wait, calls `take` on the calling thread and queues the
  /// FlightRecorder::Snapshot it returns (taken for `reason`), then returns at once; otherwise
  /// returns false without calling `take`, so a refused dump costs no copy. One thread posts (the
  /// ingress thread): room seen here cannot be used up before the snapshot is queued.
  template <class Take>
  bool post(std::string reason, Take&& take) {
    if (!has_room()) return false;
    enqueue({take(), std::move(reason)});
    return true;
  }

  /// Dumps written, failed and refused since start (any thread).
  std::uint64_t written() const { return written_.load(std::memory_order_relaxed); }
  std::uint64_t failed() const { return failed_.load(std::memory_order_relaxed); }
  std::uint64_t refused() const { return refused_.load(std::memory_order_relaxed); }

 private:
  struct Pending {
    FlightRecorder::Snapshot snapshot;
    std::string reason;
  };
  bool has_room();  // counts a refusal when not
  void enqueue(Pending pending);
  void run(const std::stop_token& stop);

  std::mutex mutex_;
  std::condition_variable_any posted_;
  std::deque<Pending> pending_;  // guarded by mutex_
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> failed_{0};
  std::atomic<std::uint64_t> refused_{0};
  std::jthread thread_;  // last: started once everything it uses exists
};

}  // namespace rsg::gateway
