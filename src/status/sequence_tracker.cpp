#include "status/sequence_tracker.hpp"

#include <algorithm>
#include <utility>

#include "rsg/wire/frame.hpp"

namespace rsg::status {
namespace {

constexpr unsigned kModulo = wire::kPacketNumberModulo;
constexpr unsigned kWindow = 64;  // bits of `arrived_`; more than any distance a frame can have
// Without time, a frame further ahead than this may instead be a late one.
constexpr unsigned kMaxAheadWithoutTime = kModulo / 2;

unsigned distance_ahead(std::uint8_t from, std::uint8_t to) { return (to - from + kModulo) % kModulo; }

}  // namespace

SequenceTracker::SequenceTracker(std::uint64_t restart_threshold_ms,
                                 std::chrono::steady_clock::duration silence)
    : restart_threshold_ms_(restart_threshold_ms), silence_(silence) {}

SequenceTracker::Verdict SequenceTracker::observe(std::uint8_t packet_number,
                                                  std::optional<std::uint64_t> time_ms,
                                                  Arrival arrival) noexcept {
  const bool was_holding = std::exchange(holding_, false);
  releases_held_ = false;
  if (!started_) {
    start(packet_number, time_ms, arrival);
    return Verdict::kInSequence;
  }
  if (invalid_credits_ != 0 && ++frames_since_invalid_ > kModulo) invalid_credits_ = 0;

  const unsigned ahead = distance_ahead(newest_packet_number_, packet_number);
  if (!time_ms && was_holding) {
    // A frame without time that goes on from the held frame's packet number once the frames with
    // time have been silent confirms the restart: otherwise the robot's own frames without time,
    // which cannot be told from the old stream's, would keep that stream alive for ever.
    const unsigned from_candidate = distance_ahead(candidate_packet_number_, packet_number);
    if (from_candidate != 0 && from_candidate <= kMaxAheadWithoutTime &&
        arrival - newest_time_arrival_ >= silence_)
      return restart(from_candidate, packet_number, time_ms, arrival, true);
  }
  // Above 1 kHz consecutive frames may share a millisecond: equal times leave it to the number.
  if (!time_ms || !newest_time_ms_ || *time_ms == *newest_time_ms_) {
    candidate_frames_ = 0;  // the stream goes on
    newest_arrival_ = std::max(newest_arrival_, arrival);
    if (ahead == 0) {
      arrive_late(0);
    } else if (ahead > kMaxAheadWithoutTime && is_missing(kModulo - ahead)) {
      // Behind only when that fills a known gap: a burst loss is never misread as old frames.
      arrive_late(kModulo - ahead);
    } else {
      advance(ahead, packet_number, time_ms, arrival);
    }
    return Verdict::kInSequence;
  }

  if (*time_ms > *newest_time_ms_) {
    if (!in_step(*newest_time_ms_, newest_time_arrival_, *time_ms, arrival))
      return another_sequence(packet_number, *time_ms, arrival, was_holding);
    candidate_frames_ = 0;
    advance(ahead == 0 ? kModulo : ahead, packet_number, time_ms, arrival);
    return Verdict::kInSequence;
  }
  // Earlier by more than a late frame can be, or after the stream fell silent (a robot restarted
  // soon after its start has times below the old ones for a while): maybe a new sequence.
  if (*newest_time_ms_ - *time_ms > restart_threshold_ms_ || arrival - newest_arrival_ >= silence_)
    return another_sequence(packet_number, *time_ms, arrival, was_holding);
  // Late: it counts in the sequence (reordered or duplicated), but the stream has moved on.
  const unsigned behind = distance_ahead(packet_number, newest_packet_number_);
  arrive_late(behind == 0 ? kModulo : behind);
  ++counts_.out_of_sequence;
  return Verdict::kOutOfSequence;
}

bool SequenceTracker::in_step(std::uint64_t from_ms, Arrival from_arrival, std::uint64_t to_ms,
                              Arrival to_arrival) const noexcept {
  // The robot's clock runs as fast as the arrival clock; `silence` allows for frames bunched up
  // on their way. Arrival times are kernel time stamps, so a busy gateway does not bunch them.
  const auto allowed =
      std::max(to_arrival - from_arrival, std::chrono::steady_clock::duration::zero()) + silence_;
  return to_ms >= from_ms && std::chrono::milliseconds(to_ms - from_ms) <= allowed;
}

SequenceTracker::Verdict SequenceTracker::another_sequence(std::uint8_t packet_number, std::uint64_t time_ms,
                                                           Arrival arrival, bool was_holding) noexcept {
  const unsigned ahead = distance_ahead(candidate_packet_number_, packet_number);
  const bool continues = candidate_frames_ > 0 && time_ms > candidate_time_ms_ && ahead != 0 &&
                         ahead <= kMaxAheadWithoutTime &&
                         in_step(candidate_time_ms_, candidate_arrival_, time_ms, arrival);
  const unsigned frames = continues ? candidate_frames_ + 1 : 1;
  const unsigned skipped = continues ? candidate_skipped_ + ahead - 1 : 0;  // in the new sequence
  // While the stream followed so far is still heard, or the new sequence has not gone on, the
  // frame is a replay or a forgery as far as anyone can tell: it changes nothing of the stream's
  // accounting. Only the frames with time are the stream's for sure.
  if (arrival - newest_time_arrival_ < silence_ || frames < kConfirmFrames) {
    candidate_frames_ = frames;
    candidate_skipped_ = skipped;
    candidate_packet_number_ = packet_number;
    candidate_time_ms_ = time_ms;
    candidate_arrival_ = arrival;
    ++counts_.out_of_sequence;
    holding_ = true;
    return Verdict::kHeld;
  }
  return restart(ahead, packet_number, time_ms, arrival, was_holding);
}

SequenceTracker::Verdict SequenceTracker::restart(unsigned ahead, std::uint8_t packet_number,
                                                  std::optional<std::uint64_t> time_ms, Arrival arrival,
                                                  bool release_held) noexcept {
  ++counts_.restarts;
  // The new sequence starts at the candidate, and what its frames skipped up to it counts lost
  // (less the invalid frames that arrived meanwhile, as in advance()).
  const std::uint64_t credits = invalid_credits_;
  const std::uint64_t skipped = candidate_skipped_;
  start(candidate_packet_number_, candidate_time_ms_, candidate_arrival_);
  const std::uint64_t covered = std::min(skipped, credits);
  counts_.lost += skipped - covered;
  invalid_credits_ = credits - covered;
  advance(ahead, packet_number, time_ms, arrival);
  releases_held_ = release_held;
  if (release_held) --counts_.out_of_sequence;  // the held frame is published after all
  return Verdict::kInSequence;
}

void SequenceTracker::start(std::uint8_t packet_number, std::optional<std::uint64_t> time_ms,
                            Arrival arrival) noexcept {
  started_ = true;
  invalid_credits_ = 0;  // nothing before the first frame (or a restart) counts as lost anyway
  newest_packet_number_ = packet_number;
  newest_time_ms_ = time_ms;
  newest_arrival_ = arrival;
  newest_time_arrival_ = arrival;
  candidate_frames_ = 0;
  arrived_ = ~std::uint64_t{0};  // nothing before the first frame is missing
  covered_ = 0;
}

void SequenceTracker::advance(unsigned distance, std::uint8_t packet_number,
                              std::optional<std::uint64_t> time_ms, Arrival arrival) noexcept {
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
  // A frame without time keeps the last one known: a stream that alternates selections is still
  // ordered by time where it can be.
  if (time_ms) {
    newest_time_ms_ = time_ms;
    newest_time_arrival_ = arrival;
  }
  newest_arrival_ = std::max(newest_arrival_, arrival);
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

}  // namespace rsg::status
