// Writes the flight recorder's dumps on a thread of its own, so that the ingress thread, which
// takes the snapshot, never waits on the disk; and bounds what they cost, so that whoever can
// flap the link or send SIGUSR1 cannot fill the disk: a minimum interval between dumps, and a cap
// on the number and bytes of rsg's own files in the folder, the oldest deleted first.
//
// Retention keeps the evidence an attacker would want gone (docs/security.md): rsg's own files are
// those named rsg_flight_*.pcap that are regular files (no symlink) owned by the gateway's user,
// and only they are counted or deleted. Of them it never deletes a file younger than
// `keep_younger_than` (an hour), the newest, nor the newest of each cause (link_down, signal); it
// deletes first the files that were followed by another within that hour (the middle of a burst)
// and only then the last file before a quiet hour (the last dump before an attack). When nothing
// may go, the new dump is not written (counted no_room): forged flaps cannot rotate out a dump
// younger than an hour, nor the one before them while the burst has files of its own to give.
#pragma once

#include <sys/types.h>

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

#include "app/repeated_log.hpp"
#include "gateway/clock.hpp"
#include "gateway/flight_recorder.hpp"

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
    /// Files younger than this are never deleted to make room (header comment).
    std::chrono::seconds keep_younger_than = kKeepYoungerThan;
  };

  /// The age under which no dump is deleted to make room for another, documented in
  /// docs/security.md: long enough for an operator alerted by a link-down to copy the file.
  static constexpr std::chrono::seconds kKeepYoungerThan = std::chrono::hours(1);

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
  /// Dumps not written because every file in the folder is protected (header comment).
  std::uint64_t no_room() const { return no_room_.load(std::memory_order_relaxed); }

 private:
  struct Pending {
    FlightRecorder::Snapshot snapshot;
    std::string reason;
  };
  bool has_room();  // counts a refusal when not
  void enqueue(Pending pending);
  void run(const std::stop_token& stop);
  // Deletes rsg's files in the folder that retention lets go, oldest first, until one of `bytes`
  // more fits both caps; false when they cannot be made to fit.
  // @throws std::filesystem::filesystem_error when the folder cannot be listed or a file deleted.
  bool make_room(std::uintmax_t bytes);

  Options options_;
  ::uid_t owner_;                                   // the gateway's user: whose files are rsg's
  std::optional<Clock::time_point> last_accepted_;  // the posting thread's
  // The writing thread's lines, paced by app::RepeatedLog.
  app::RepeatedLog written_log_, deleted_log_, no_room_log_, failed_log_;
  std::mutex mutex_;
  std::condition_variable_any posted_;
  std::deque<Pending> pending_;  // guarded by mutex_
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> failed_{0};
  std::atomic<std::uint64_t> refused_{0};
  std::atomic<std::uint64_t> throttled_{0};
  std::atomic<std::uint64_t> deleted_{0};
  std::atomic<std::uint64_t> no_room_{0};
  std::jthread thread_;  // last: started once everything it uses exists
};

}  // namespace rsg::gateway
