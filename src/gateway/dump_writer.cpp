#include "gateway/dump_writer.hpp"

#include <pthread.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <exception>
#include <utility>
#include <vector>

namespace rsg::gateway {
namespace {

// rsg's own dump files (FlightRecorder::snapshot names them): nothing else in the folder is
// counted or deleted. One that vanishes while the folder is read is not there.
bool is_dump_file(const std::filesystem::directory_entry& entry) {
  const std::string name = entry.path().filename().string();
  std::error_code error;
  return name.starts_with("rsg_flight_") && name.ends_with(".pcap") && entry.is_regular_file(error);
}

}  // namespace

DumpWriter::DumpWriter(Options options)
    : options_(std::move(options)), thread_([this](const std::stop_token& stop) { run(stop); }) {}

// std::jthread asks run() to stop and joins it; run() writes what is pending first.
DumpWriter::~DumpWriter() = default;

bool DumpWriter::has_room() {
  const std::lock_guard lock(mutex_);
  if (pending_.size() < kMaxPending) return true;
  refused_.fetch_add(1, std::memory_order_relaxed);
  return false;
}

void DumpWriter::enqueue(Pending pending) {
  {
    const std::lock_guard lock(mutex_);
    pending_.push_back(std::move(pending));
  }
  posted_.notify_one();
}

void DumpWriter::make_room(std::uintmax_t bytes) {
  struct File {
    std::filesystem::file_time_type time;
    std::filesystem::path path;
    std::uintmax_t size;
  };
  std::vector<File> files;
  std::uintmax_t total = 0;
  for (const auto& entry : std::filesystem::directory_iterator(options_.dir)) {
    if (!is_dump_file(entry)) continue;
    std::error_code error;
    const auto time = entry.last_write_time(error);
    const std::uintmax_t size = error ? 0 : entry.file_size(error);
    if (error) continue;
    files.push_back({time, entry.path(), size});
    total += size;
  }
  std::ranges::sort(files, [](const File& a, const File& b) {
    return a.time != b.time ? a.time < b.time : a.path < b.path;
  });
  std::size_t left = files.size();
  for (const File& file : files) {
    if (left < options_.max_files && total + bytes <= options_.max_bytes) break;
    if (std::filesystem::remove(file.path)) deleted_.fetch_add(1, std::memory_order_relaxed);
    total -= file.size;
    --left;
  }
  const std::uint64_t deleted = deleted_.load(std::memory_order_relaxed);
  if (deleted != deleted_logged_ && deleted_log_.allow(Clock::now())) {
    spdlog::info(
        "flight recorder: deleted {} of its oldest files in {} ({} since start) to keep at most {} files and "
        "{} MiB (--pcap-max-files, --pcap-max-mb)",
        deleted - deleted_logged_, options_.dir.string(), deleted, options_.max_files,
        options_.max_bytes >> 20);
    deleted_logged_ = deleted;
  }
}

void DumpWriter::run(const std::stop_token& stop) {
  ::pthread_setname_np(::pthread_self(), "rsg-dump");  // top -H, perf, tests find it by name
  for (;;) {
    Pending next;
    {
      std::unique_lock lock(mutex_);
      posted_.wait(lock, stop, [this] { return !pending_.empty(); });
      if (pending_.empty()) return;  // stopped, nothing left to write
      next = std::move(pending_.front());
      pending_.pop_front();
    }
    try {
      // A ring larger than the byte cap: the newest seconds are what a dump is for.
      if (const std::size_t dropped = FlightRecorder::keep_newest(next.snapshot, options_.max_bytes))
        spdlog::warn(
            "flight recorder ({}): {} oldest datagrams left out to keep the file within --pcap-max-mb {}",
            next.reason, dropped, options_.max_bytes >> 20);
      make_room(FlightRecorder::file_bytes(next.snapshot));
      const FlightRecorder::Dump dumped = FlightRecorder::write(next.snapshot);
      written_.fetch_add(1, std::memory_order_relaxed);
      spdlog::info("flight recorder ({}): {} datagrams in {}", next.reason, dumped.frames,
                   dumped.path.string());
    } catch (const std::exception& error) {
      failed_.fetch_add(1, std::memory_order_relaxed);
      spdlog::error("flight recorder ({}): {}", next.reason, error.what());
    }
  }
}

}  // namespace rsg::gateway
