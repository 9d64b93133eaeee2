#include "dump_writer.hpp"

#include <pthread.h>
#include <spdlog/spdlog.h>

#include <exception>
#include <utility>

namespace rsg::gateway {

DumpWriter::DumpWriter() : thread_([this](const std::stop_token& stop) { run(stop); }) {}

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
