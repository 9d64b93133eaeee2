#include "sequence_tracker.hpp"

#include <algorithm>

#include "rsg/wire/frame.hpp"

namespace rsg::gateway {
namespace {

constexpr unsigned kModulo = wire::kPacketNumberModulo;
constexpr unsigned kWindow = 64;  // bits of `arrived_`; more than any distance a frame can have
// Without time, a frame further ahead than this may instead be a late one.
constexpr unsigned kMaxAheadWithoutTime = kModulo / 2;

unsigned distance_ahead(std::uint8_t from, std::uint8_t to) { return (to - from + kModulo) % kModulo; }

}  // namespace

SequenceTracker::SequenceTracker(std::uint64_t restart_threshold_ms)
    : restart_threshold_ms_(restart_threshold_ms) {}

void SequenceTracker::observe(std::uint8_t packet_number, std::optional<std::uint64_t> time_ms) noexcept {
  if (!started_) return start(packet_number, time_ms);
  if (invalid_credits_ != 0 && ++frames_since_invalid_ > kModulo) invalid_credits_ = 0;

  const unsigned ahead = distance_ahead(newest_packet_number_, packet_number);
  // Above 1 kHz consecutive frames may share a millisecond: equal times leave it to the number.
  if (!time_ms || !newest_time_ms_ || *time_ms == *newest_time_ms_) {
    if (ahead == 0) return arrive_late(0);
    // Behind only when that fills a known gap: a burst loss is never misread as old frames.
    if (ahead > kMaxAheadWithoutTime && is_missing(kModulo - ahead)) return arrive_late(kModulo - ahead);
    return advance(ahead, packet_number, time_ms);
  }

  if (*time_ms > *newest_time_ms_) return advance(ahead == 0 ? kModulo : ahead, packet_number, time_ms);
  if (*newest_time_ms_ - *time_ms > restart_threshold_ms_) {
    ++counts_.restarts;
    return start(packet_number, time_ms);
  }
  const unsigned behind = distance_ahead(packet_number, newest_packet_number_);
  arrive_late(behind == 0 ? kModulo : behind);
}

void SequenceTracker::start(std::uint8_t packet_number, std::optional<std::uint64_t> time_ms) noexcept {
  started_ = true;
  invalid_credits_ = 0;  // nothing before the first frame (or a restart) counts as lost anyway
  newest_packet_number_ = packet_number;
  newest_time_ms_ = time_ms;
  arrived_ = ~std::uint64_t{0};  // nothing before the first frame is missing
  covered_ = 0;
}

void SequenceTracker::advance(unsigned distance, std::uint8_t packet_number,
                              std::optional<std::uint64_t> time_ms) noexcept {
  // Invalid frames not yet matched cover skipped positions, which are not counted lost. Which
  // positions they held cannot be known: the oldest are marked covered, and stay missing, so that
  // a late valid frame is still recognised (arrive_late moves the cover).
  const unsigned skipped = distance - 1;
  const unsigned covered = static_cast<unsigned>(std::min<std::uint64_t>(skipped, invalid_credits_));
  invalid_credits_ -= covered;
  counts_.lost += skipped - covered;
  arrived_ = distance >= kWindow ? 0 : arrived_ << distance;
  covered_ = distance >= kWindow ? 0 : covered_ << distance;
  for (unsigned age = distance - covered; age < distance && age < kWindow; ++age)
    covered_ |= std::uint64_t{1} << age;
  arrived_ |= 1U;
  newest_packet_number_ = packet_number;
  newest_time_ms_ = time_ms;
}

bool SequenceTracker::is_missing(unsigned age) const noexcept { return !((arrived_ >> age) & 1U); }

void SequenceTracker::arrive_late(unsigned age) noexcept {
  const std::uint64_t bit = std::uint64_t{1} << age;
  if (arrived_ & bit) {
    ++counts_.duplicated;
    return;
  }
  arrived_ |= bit;
  ++counts_.reordered;
  if (!(covered_ & bit)) {
    --counts_.lost;  // it was counted lost when a later frame skipped it
    return;
  }
  // An invalid frame covered this position, so it held another one: a missing position not yet
  // covered, now no longer lost. Without one, it was no frame of this stream after all.
  covered_ &= ~bit;
  const std::uint64_t uncovered = ~arrived_ & ~covered_;
  if (uncovered != 0) {
    covered_ |= uncovered & (~uncovered + 1);  // the newest such position
    --counts_.lost;
  }
}

}  // namespace rsg::gateway
