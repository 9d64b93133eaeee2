#include "app/recording_order.hpp"

#include <algorithm>
#include <utility>

namespace rsg::app {

void PublicationOrder::add(const WriterId& writer, bool contiguous, std::span<const std::uint8_t> payload,
                           Sample sample) {
  Stream& stream = streams_[Key{sample.channel, writer}];
  stream.channel = sample.channel;
  stream.contiguous = contiguous;
  Counts& counts = counts_[sample.channel];
  if (stream.started && sample.sequence < stream.next) {
    // Its place in the file has passed: written now, it would break the order a replay relies on.
    if (sample.sequence < stream.first_written)
      ++counts.before_start;
    else if (stream.skipped.erase(sample.sequence) > 0)
      ++counts.late;
    return;  // otherwise written already
  }
  if (stream.pending.contains(sample.sequence)) return;  // the same sample again (not seen from DDS)
  if (!spare_.empty()) {
    sample.payload = std::move(spare_.back());
    spare_.pop_back();
  }
  sample.payload.assign(payload.begin(), payload.end());
  stream.log_times.insert(sample.log_time);
  const std::uint64_t sequence = sample.sequence;
  stream.pending.emplace(sequence, std::move(sample));
  ++held_;
}

void PublicationOrder::start(Stream& stream) {
  if (stream.contiguous) {
    // What arrived below the last hole is the writer's history still arriving: leave it out, so
    // that the recording starts with an unbroken run (see the header).
    auto run_start = stream.pending.begin();
    for (auto it = stream.pending.begin(), next = std::next(it); next != stream.pending.end(); ++it, ++next)
      if (next->first != it->first + 1) run_start = next;
    while (stream.pending.begin() != run_start) {
      ++counts_[stream.channel].before_start;
      recycle(pop(stream));
    }
  }
  stream.started = true;
  stream.first_written = stream.pending.begin()->first;
  stream.next = stream.first_written;
}

PublicationOrder::Sample PublicationOrder::pop(Stream& stream) {
  auto node = stream.pending.extract(stream.pending.begin());
  Sample sample = std::move(node.mapped());
  stream.log_times.erase(stream.log_times.find(sample.log_time));
  --held_;
  if (stream.started) {
    if (stream.contiguous && sample.sequence > stream.next)
      counts_[stream.channel].gaps += sample.sequence - stream.next;
    // Remembered so that one arriving after all is told from a sample written before.
    const std::uint64_t from =
        sample.sequence - std::min<std::uint64_t>(sample.sequence - stream.next, kSkippedKept);
    for (std::uint64_t skipped = std::max(stream.next, from); skipped < sample.sequence; ++skipped) {
      if (stream.skipped.size() == kSkippedKept) stream.skipped.erase(stream.skipped.begin());
      stream.skipped.insert(skipped);
    }
    stream.next = sample.sequence + 1;
  }
  return sample;
}

void PublicationOrder::recycle(Sample&& sample) {
  if (spare_.size() < 64) spare_.push_back(std::move(sample.payload));
}

PublicationOrder::Counts PublicationOrder::counts(std::uint16_t channel) const {
  const auto it = counts_.find(channel);
  return it == counts_.end() ? Counts{} : it->second;
}

}  // namespace rsg::app
