#include "tests/bench/e2e/latency_log.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <stdexcept>

namespace rsg::bench {
namespace {

// Nearest rank: the smallest sample with at least `fraction` of the samples at or below it.
double percentile_us(const std::vector<std::int64_t>& sorted, double fraction) {
  const auto rank = static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(sorted.size())));
  return static_cast<double>(sorted[std::clamp<std::size_t>(rank, 1, sorted.size()) - 1]) / 1e3;
}

}  // namespace

LatencyLog::LatencyLog(std::uint64_t warmup, std::uint64_t measured)
    : warmup_(warmup), latency_ns_(warmup + measured) {
  for (auto& slot : latency_ns_) slot.store(kMissing, std::memory_order_relaxed);
}

void LatencyLog::record(const Stamp& stamp, std::int64_t received_ns) noexcept {
  if (stamp.index >= latency_ns_.size()) return;  // not ours: a stale writer of an earlier run
  std::int64_t expected = kMissing;
  if (latency_ns_[stamp.index].compare_exchange_strong(expected, received_ns - stamp.sent_ns,
                                                       std::memory_order_relaxed))
    arrived_.fetch_add(1, std::memory_order_release);
  else
    duplicates_.fetch_add(1, std::memory_order_relaxed);
}

std::vector<std::int64_t> LatencyLog::measured_sorted() const {
  std::vector<std::int64_t> latencies;
  latencies.reserve(latency_ns_.size() - warmup_);
  for (std::size_t i = warmup_; i < latency_ns_.size(); ++i)
    if (const std::int64_t ns = latency_ns_[i].load(std::memory_order_relaxed); ns != kMissing)
      latencies.push_back(ns);
  std::sort(latencies.begin(), latencies.end());
  return latencies;
}

LatencySummary LatencyLog::summarize() const {
  const std::vector<std::int64_t> sorted = measured_sorted();
  LatencySummary summary;
  summary.sent = latency_ns_.size() - warmup_;
  summary.received = sorted.size();
  summary.lost = summary.sent - summary.received;
  summary.duplicates = duplicates_.load(std::memory_order_relaxed);
  if (sorted.empty()) return summary;
  summary.min_us = static_cast<double>(sorted.front()) / 1e3;
  summary.mean_us = static_cast<double>(std::accumulate(sorted.begin(), sorted.end(), std::int64_t{0})) /
                    static_cast<double>(sorted.size()) / 1e3;
  summary.p50_us = percentile_us(sorted, 0.50);
  summary.p90_us = percentile_us(sorted, 0.90);
  summary.p99_us = percentile_us(sorted, 0.99);
  summary.p999_us = percentile_us(sorted, 0.999);
  summary.max_us = static_cast<double>(sorted.back()) / 1e3;
  return summary;
}

void LatencyLog::write_cdf(const std::filesystem::path& file, std::size_t body_points) const {
  const std::vector<std::int64_t> sorted = measured_sorted();
  std::ofstream out(file);
  out << "# latency_us fraction_at_or_below (" << sorted.size() << " frames)\n";
  const std::size_t tail_start = sorted.size() - sorted.size() / 100;
  const std::size_t stride = std::max<std::size_t>(1, tail_start / std::max<std::size_t>(body_points, 1));
  for (std::size_t i = 0; i < sorted.size(); ++i)
    if (i >= tail_start || i % stride == 0)
      out << static_cast<double>(sorted[i]) / 1e3 << ' '
          << static_cast<double>(i + 1) / static_cast<double>(sorted.size()) << '\n';
  if (!out) throw std::runtime_error(file.string() + ": cannot write");
}

}  // namespace rsg::bench
