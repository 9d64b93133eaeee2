// The order rsg_record writes samples in: each writer's samples in publication (sequence number)
// order, whatever order DDS delivered them in.
//
// DDS does not deliver a writer's samples in sequence order at every moment. A reliable reader that
// joins a running writer gets the live samples at once, while the writer's heartbeat makes it ask for
// the samples before them, which arrive later (on a loaded host tens of milliseconds later, a hundred
// samples back). Written in arrival order, such a recording jumps back in sequence, and replaying it
// into a gateway counts those frames as duplicated or reordered and the jump forward again as lost.
//
// So every sample waits in a per-writer buffer, sorted by sequence number, until the oldest sample
// of that writer has waited `hold` since DDS received it; then the writer's samples go out in
// sequence order up to the first one not yet due. A sample older than one already written arrived
// too late for its place: it is left out and counted (before the recording's first sample of its
// writer: `before_start`; after it: `late`), never written out of order.
//
// A stream that is contiguous by nature (every sample of a writer, no view) also starts cleanly: at
// its first release the samples before the last hole in what has arrived are left out (they are
// the writer's history trickling in as the reader joins, not yet complete), so that a recording
// begins with an unbroken run, and every hole after that is a sample the recorder never got: `gaps`.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <map>
#include <set>
#include <span>
#include <vector>

namespace rsg::app {

class PublicationOrder {
 public:
  /// A DDS writer's GUID (prefix and entity id), or any 16 bytes that tell writers apart.
  using WriterId = std::array<std::uint8_t, 16>;

  struct Sample {
    std::uint16_t channel = 0;
    std::uint64_t sequence = 0;
    std::uint64_t log_time = 0;  ///< when DDS received it, ns since the epoch: what `hold` counts from
    std::uint64_t publish_time = 0;
    std::vector<std::uint8_t> payload;
  };

  /// Per channel: what could not be written in order.
  struct Counts {
    std::uint64_t gaps = 0;  ///< sequence numbers skipped between written samples (contiguous streams)
    std::uint64_t before_start = 0;  ///< arrived after their writer's first written sample, older than it
    std::uint64_t late = 0;          ///< arrived after a later sample was written (they are in `gaps` too)
  };

  explicit PublicationOrder(std::chrono::nanoseconds hold)
      : hold_ns_(static_cast<std::uint64_t>(hold.count())) {}

  /// Takes a sample of `writer` on `sample.channel`. `contiguous`: the writer's sequence numbers on
  /// this channel have no holes of their own (no view filters them), so holes are losses.
  void add(const WriterId& writer, bool contiguous, std::span<const std::uint8_t> payload, Sample sample);

  /// Calls `write(const Sample&)` for every sample that is due at `now_ns` (same clock as log_time),
  /// in order: per writer by sequence, across writers by log time. `write` may throw; the sample it
  /// threw on counts as written.
  template <typename Write>
  void release(std::uint64_t now_ns, Write&& write) {
    release_until(now_ns, false, write);
  }
  /// Every sample held, in order (at the end of a recording).
  template <typename Write>
  void release_all(Write&& write) {
    release_until(0, true, write);
  }

  Counts counts(std::uint16_t channel) const;
  /// Samples held now.
  std::size_t held() const { return held_; }

 private:
  struct Stream {
    std::uint16_t channel = 0;
    bool contiguous = false;
    bool started = false;
    std::uint64_t first_written = 0;          // once started
    std::uint64_t next = 0;                   // the sequence number after the last one written, once started
    std::map<std::uint64_t, Sample> pending;  // by sequence number
    std::multiset<std::uint64_t> log_times;   // of `pending`: the oldest decides when the stream is due
    std::set<std::uint64_t> skipped;          // the latest sequence numbers given up (at most kSkippedKept)
  };
  static constexpr std::size_t kSkippedKept = 4096;
  using Key = std::pair<std::uint16_t, WriterId>;

  bool due(const Stream& stream, std::uint64_t now_ns, bool all) const {
    return !stream.pending.empty() && (all || *stream.log_times.begin() + hold_ns_ <= now_ns);
  }
  void start(Stream& stream);
  Sample pop(Stream& stream);
  void recycle(Sample&& sample);

  template <typename Write>
  void release_until(std::uint64_t now_ns, bool all, Write& write) {
    for (;;) {
      Stream* next = nullptr;
      for (auto& [key, stream] : streams_) {
        if (!due(stream, now_ns, all)) continue;
        if (!stream.started) start(stream);
        if (stream.pending.empty()) continue;
        if (next == nullptr ||
            stream.pending.begin()->second.log_time < next->pending.begin()->second.log_time)
          next = &stream;
      }
      if (next == nullptr) return;
      Sample sample = pop(*next);
      write(static_cast<const Sample&>(sample));
      recycle(std::move(sample));
    }
  }

  std::uint64_t hold_ns_;
  std::map<Key, Stream> streams_;
  std::map<std::uint16_t, Counts> counts_;
  std::vector<std::vector<std::uint8_t>> spare_;  // payload buffers to reuse
  std::size_t held_ = 0;
};

}  // namespace rsg::app
