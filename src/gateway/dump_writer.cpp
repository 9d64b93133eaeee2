#include "gateway/dump_writer.hpp"

#include <pthread.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <exception>
#include <set>
#include <string_view>
#include <utility>
#include <vector>

namespace rsg::gateway {
namespace {

// One of rsg's own files in the folder, as retention sees it.
struct OwnFile {
  std::int64_t mtime_ns;  // the file's own time: when it was written
  std::filesystem::path path;
  std::uintmax_t size;
  std::string cause;  // the reason in the name: rsg_flight_<time>_<N>_<cause>.pcap
};

// rsg's own dump files (FlightRecorder::snapshot names them) -- the name, a regular file (not a
// symlink, whose target may be anything) and the gateway's user as owner -- and nothing else in
// the folder: a file another user planted, however it is named or dated, is neither counted nor
// deleted. One that vanishes while the folder is read is not there.
std::optional<OwnFile> own_file(const std::filesystem::directory_entry& entry, ::uid_t owner) {
  const std::string name = entry.path().filename().string();
  if (!name.starts_with("rsg_flight_") || !name.ends_with(".pcap")) return std::nullopt;
  struct ::stat info {};
  if (::lstat(entry.path().c_str(), &info) != 0 || !S_ISREG(info.st_mode) || info.st_uid != owner)
    return std::nullopt;
  // The cause follows the third underscore after the prefix's: time, N, cause.
  std::string cause;
  std::size_t at = std::string_view("rsg_flight_").size();
  for (int field = 0; field < 2 && at != std::string::npos; ++field) {
    at = name.find('_', at);
    if (at != std::string::npos) ++at;
  }
  if (at != std::string::npos) cause = name.substr(at, name.size() - at - std::string_view(".pcap").size());
  return OwnFile{std::int64_t{info.st_mtim.tv_sec} * 1'000'000'000 + info.st_mtim.tv_nsec, entry.path(),
                 static_cast<std::uintmax_t>(info.st_size), std::move(cause)};
}

std::int64_t unix_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// "; N such lines since the last one", for a line app::RepeatedLog paced.
std::string since_last(std::uint64_t n, std::string_view what) {
  return n > 1 ? "; " + std::to_string(n) + " " + std::string(what) + " since the last such line" : "";
}

}  // namespace

DumpWriter::DumpWriter(Options options)
    : options_(std::move(options)),
      owner_(::geteuid()),
      thread_([this](const std::stop_token& stop) { run(stop); }) {}

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

bool DumpWriter::make_room(std::uintmax_t bytes) {
  std::vector<OwnFile> files;
  std::uintmax_t total = 0;
  for (const auto& entry : std::filesystem::directory_iterator(options_.dir)) {
    if (auto file = own_file(entry, owner_)) {
      total += file->size;
      files.push_back(std::move(*file));
    }
  }
  std::ranges::sort(files, [](const OwnFile& a, const OwnFile& b) {
    return a.mtime_ns != b.mtime_ns ? a.mtime_ns < b.mtime_ns : a.path < b.path;
  });
  const std::int64_t now = unix_now_ns();
  const std::int64_t keep =
      std::chrono::duration_cast<std::chrono::nanoseconds>(options_.keep_younger_than).count();
  // Never deleted: younger than `keep` (a time in the future included), the newest, the newest of
  // each cause. Deleted last: a file no other followed within `keep` (the last before a quiet hour).
  std::vector<bool> kept(files.size(), false), last_before_quiet(files.size(), false);
  std::set<std::string, std::less<>> causes;
  for (std::size_t i = files.size(); i-- > 0;) {
    kept[i] = i + 1 == files.size() || now - files[i].mtime_ns < keep || causes.insert(files[i].cause).second;
    last_before_quiet[i] = i + 1 < files.size() && files[i + 1].mtime_ns - files[i].mtime_ns >= keep;
  }
  std::size_t left = files.size();
  const auto fits = [&] { return left < options_.max_files && total + bytes <= options_.max_bytes; };
  std::uint64_t deleted_now = 0;
  for (const bool quiet_ones : {false, true}) {
    for (std::size_t i = 0; i < files.size() && !fits(); ++i) {
      if (kept[i] || last_before_quiet[i] != quiet_ones) continue;
      if (std::filesystem::remove(files[i].path)) {
        deleted_.fetch_add(1, std::memory_order_relaxed);
        ++deleted_now;
      }
      total -= files[i].size;
      --left;
    }
  }
  if (const auto n = deleted_log_.take(Clock::now(), deleted_now))
    spdlog::info(
        "flight recorder: deleted {} of its oldest files in {} since the last such line ({} since start) to "
        "keep at most {} files and {} MiB (--pcap-max-files, --pcap-max-mb)",
        n, options_.dir.string(), deleted_.load(std::memory_order_relaxed), options_.max_files,
        options_.max_bytes >> 20);
  return fits();
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
      if (!make_room(FlightRecorder::file_bytes(next.snapshot))) {
        no_room_.fetch_add(1, std::memory_order_relaxed);
        if (const auto n = no_room_log_.take(Clock::now()))
          spdlog::warn(
              "flight recorder ({}): not dumped, {} holds --pcap-max-files {} / --pcap-max-mb {} of files "
              "retention keeps (younger than {} s, the newest, the last before a quiet spell){}",
              next.reason, options_.dir.string(), options_.max_files, options_.max_bytes >> 20,
              options_.keep_younger_than.count(), since_last(n, "dumps not written"));
        continue;
      }
      const FlightRecorder::Dump dumped = FlightRecorder::write(next.snapshot);
      written_.fetch_add(1, std::memory_order_relaxed);
      if (const auto n = written_log_.take(Clock::now()))
        spdlog::info("flight recorder ({}): {} datagrams in {}{}", next.reason, dumped.frames,
                     dumped.path.string(), since_last(n, "dumps written"));
    } catch (const std::exception& error) {
      failed_.fetch_add(1, std::memory_order_relaxed);
      if (const auto n = failed_log_.take(Clock::now()))
        spdlog::error("flight recorder ({}): {}{}", next.reason, error.what(), since_last(n, "dumps failed"));
    }
  }
}

}  // namespace rsg::gateway
