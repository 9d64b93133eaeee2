// A latency histogram with fixed buckets, for the per-frame durations the metrics export as
// Prometheus histograms (rsg_ingress_delay_seconds, rsg_frame_age_seconds).
//
// Recorded on the ingress thread for every valid frame, so `record` allocates nothing, takes no
// lock and costs a handful of comparisons; the gateway copies the whole histogram (a fixed-size
// array) into the metrics snapshot on that same thread, so no atomics are needed either.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>

namespace rsg::gateway {

class LatencyHistogram {
 public:
  /// The buckets' upper bounds ("le"), in ns: 50 us to 1 s, roughly 1-2.5-5 per decade. A 1 kHz
  /// gateway's frames are meant to leave within 1 ms; the buckets above tell how far it fell behind.
  static constexpr std::array<std::int64_t, 14> kBoundsNs = {
      50'000,     100'000,    250'000,    500'000,     1'000'000,   2'500'000,   5'000'000,
      10'000'000, 25'000'000, 50'000'000, 100'000'000, 250'000'000, 500'000'000, 1'000'000'000};

  /// Counts `duration` in the first bucket whose bound is not below it (a negative one as 0).
  void record(std::chrono::nanoseconds duration) noexcept {
    const std::int64_t ns = duration.count() < 0 ? 0 : duration.count();
    std::size_t bucket = 0;
    while (bucket < kBoundsNs.size() && ns > kBoundsNs[bucket]) ++bucket;
    ++counts_[bucket];
    ++count_;
    sum_ns_ += static_cast<std::uint64_t>(ns);
  }

  /// Observations in bucket `i` alone (not cumulative); bucket kBoundsNs.size() is above the last bound.
  std::uint64_t bucket_count(std::size_t i) const { return counts_[i]; }
  std::uint64_t count() const { return count_; }
  double sum_seconds() const { return static_cast<double>(sum_ns_) / 1e9; }

 private:
  std::array<std::uint64_t, kBoundsNs.size() + 1> counts_{};
  std::uint64_t count_ = 0;
  std::uint64_t sum_ns_ = 0;
};

}  // namespace rsg::gateway
