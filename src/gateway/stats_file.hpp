// The stats file (--stats-file): the gateway's counters as one JSON object, rewritten every status
// period for scripts, health checks and tests.
#pragma once

#include <condition_variable>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <thread>

#include "status/stats.hpp"

namespace rsg::gateway {

/// Writes the stats file aside and renames it over the old one, so that a reader never sees half a
/// file. The periodic writes run on a thread of their own: replacing a file can wait on the disk for
/// milliseconds (the file system freeing the old file's blocks), and the ingress thread that
/// reports the stats must never wait on a disk. Failures are logged once per cause, never thrown:
/// the gateway keeps publishing without its stats file.
class StatsFile {
 public:
  /// Starts the writer thread; with an empty `path` nothing is ever written.
  explicit StatsFile(std::string path);
  /// Writes what is still pending, then stops the thread.
  ~StatsFile();
  StatsFile(const StatsFile&) = delete;
  StatsFile& operator=(const StatsFile&) = delete;

  /// Writes `stats` now, on the calling thread (the first file before READY, the last at stop);
  /// anything posted before and not yet written is dropped, never written after it.
  void write_now(const status::GatewayStats& stats);

  /// Hands `stats` to the writer thread and returns at once; a later post replaces one not yet
  /// written.
  void post(const status::GatewayStats& stats);

 private:
  void run(const std::stop_token& stop);
  void write(const status::GatewayStats& stats);  // with file_mutex_ held

  const std::string path_;
  std::mutex file_mutex_;  // one write of the file at a time, in the order of the calls
  int last_errno_ = 0;     // of the last failed write; 0: it worked (guarded by file_mutex_)
  std::mutex pending_mutex_;
  std::condition_variable_any posted_;
  std::optional<status::GatewayStats> pending_;  // guarded by pending_mutex_
  std::jthread thread_;                          // last: started once everything it uses exists
};

}  // namespace rsg::gateway
