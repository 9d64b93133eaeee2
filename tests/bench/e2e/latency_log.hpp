// One slot per frame of a run, filled by whichever thread receives the frame.
//
// The slots are allocated before the first frame, so recording neither allocates nor locks: a
// receiving thread that allocated or waited would add its own latency to what it measures. The
// first `warmup` frames (discovery settling, caches and page faults) are received but not
// summarised.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "tests/bench/e2e/stamped_frames.hpp"

namespace rsg::bench {

struct LatencySummary {
  std::uint64_t sent = 0;        ///< measured frames (warm-up excluded)
  std::uint64_t received = 0;    ///< distinct measured frames that arrived
  std::uint64_t lost = 0;        ///< sent - received
  std::uint64_t duplicates = 0;  ///< frames that arrived more than once (any phase)
  double min_us = 0, mean_us = 0, p50_us = 0, p90_us = 0, p99_us = 0, p999_us = 0, max_us = 0;
};

class LatencyLog {
 public:
  LatencyLog(std::uint64_t warmup, std::uint64_t measured);

  /// Called by the receiving thread(s) as soon as a frame is in hand.
  void record(const Stamp& stamp, std::int64_t received_ns) noexcept;

  /// Frames (warm-up included) that have arrived so far.
  std::uint64_t arrived() const { return arrived_.load(std::memory_order_acquire); }
  std::uint64_t expected() const { return latency_ns_.size(); }

  /// Percentiles over the measured frames; call once receiving has stopped or settled.
  LatencySummary summarize() const;

  /// The measured latencies as an empirical CDF ("latency_us fraction" lines, gnuplot-ready):
  /// every point of the tail above p99, at most `body_points` below it.
  void write_cdf(const std::filesystem::path& file, std::size_t body_points = 2000) const;

 private:
  static constexpr std::int64_t kMissing = INT64_MIN;
  std::vector<std::int64_t> measured_sorted() const;

  std::uint64_t warmup_;
  std::vector<std::atomic<std::int64_t>> latency_ns_;  // kMissing until the frame arrives
  std::atomic<std::uint64_t> arrived_{0};
  std::atomic<std::uint64_t> duplicates_{0};
};

}  // namespace rsg::bench
