#include "gateway/stats_file.hpp"

#include <pthread.h>
#include <spdlog/spdlog.h>

#include <cerrno>
#include <cstdio>
#include <utility>

#include "gateway/errno_text.hpp"

namespace rsg::gateway {

StatsFile::StatsFile(std::string path) : path_(std::move(path)) {
  if (!path_.empty()) thread_ = std::jthread([this](const std::stop_token& stop) { run(stop); });
}

// std::jthread asks run() to stop and joins it; run() writes what is pending first.
StatsFile::~StatsFile() = default;

void StatsFile::write_now(const status::GatewayStats& stats) {
  if (path_.empty()) return;
  const std::lock_guard file(file_mutex_);
  {
    const std::lock_guard lock(pending_mutex_);
    pending_.reset();  // older than `stats`
  }
  write(stats);
}

void StatsFile::post(const status::GatewayStats& stats) {
  if (path_.empty()) return;
  {
    const std::lock_guard lock(pending_mutex_);
    pending_ = stats;
  }
  posted_.notify_one();
}

void StatsFile::run(const std::stop_token& stop) {
  ::pthread_setname_np(::pthread_self(), "rsg-stats");  // top -H, perf, tests find it by name
  for (;;) {
    {
      std::unique_lock lock(pending_mutex_);
      posted_.wait(lock, stop, [this] { return pending_.has_value(); });
      if (!pending_) return;  // stopped, nothing left to write
    }
    // The file first, then what is pending: a write_now() in between has taken it, and older stats
    // are never written after newer ones.
    const std::lock_guard file(file_mutex_);
    std::optional<status::GatewayStats> stats;
    {
      const std::lock_guard lock(pending_mutex_);
      stats.swap(pending_);
    }
    if (stats) write(*stats);
  }
}

void StatsFile::write(const status::GatewayStats& stats) {
  const std::string partial = path_ + ".partial";
  const std::string text = to_json(stats) + '\n';
  const auto failed = [&](const std::string& file) {
    const int error = errno;
    // Once per cause, not every second; and once again when it works again.
    if (std::exchange(last_errno_, error) != error)
      spdlog::warn("cannot write {}: {}", file, errno_text(error));
  };
  std::FILE* out = std::fopen(partial.c_str(), "w");
  if (out == nullptr) return failed(partial);
  const bool written = std::fwrite(text.data(), 1, text.size(), out) == text.size();
  const int write_error = errno;
  if (std::fclose(out) != 0 || !written) {
    if (!written) errno = write_error;
    return failed(partial);
  }
  if (std::rename(partial.c_str(), path_.c_str()) != 0) return failed(path_);
  if (std::exchange(last_errno_, 0) != 0) spdlog::info("writing {} again", path_);
}

}  // namespace rsg::gateway
