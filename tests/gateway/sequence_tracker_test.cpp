#include "sequence_tracker.hpp"

#include <gtest/gtest.h>

#include <optional>
#include <vector>

namespace rsg::gateway {
namespace {

using Counts = SequenceTracker::Counts;

// A frame as the robot numbers it: its index in the robot's stream gives packet number and time.
struct Sent {
  std::uint64_t index;
  bool with_time = true;
};

Counts track(const std::vector<Sent>& arrivals, std::uint64_t first_time_ms = 5000) {
  SequenceTracker tracker;
  for (const Sent& frame : arrivals)
    tracker.observe(
        static_cast<std::uint8_t>(frame.index % 16),
        frame.with_time ? std::optional<std::uint64_t>(first_time_ms + frame.index) : std::nullopt);
  return tracker.counts();
}

std::vector<Sent> in_order(std::uint64_t count, bool with_time = true) {
  std::vector<Sent> frames;
  for (std::uint64_t i = 0; i < count; ++i) frames.push_back({i, with_time});
  return frames;
}

TEST(SequenceTracker, InOrderStreamAcrossManyWrapsCountsNothing) {
  EXPECT_EQ(track(in_order(1000)), Counts{});
  EXPECT_EQ(track(in_order(1000, false)), Counts{});
}

TEST(SequenceTracker, FirstFrameMayHaveAnyPacketNumber) { EXPECT_EQ(track({{7}, {8}, {9}}), Counts{}); }

TEST(SequenceTracker, GapsCountAsLost) {
  for (const bool with_time : {true, false}) {
    const Counts counts =
        track({{0, with_time}, {1, with_time}, {5, with_time}, {6, with_time}, {8, with_time}});
    EXPECT_EQ(counts.lost, 4U) << "with_time " << with_time;
    EXPECT_EQ(counts.duplicated + counts.reordered + counts.restarts, 0U);
  }
}

TEST(SequenceTracker, RepeatedFrameIsADuplicate) {
  EXPECT_EQ(track({{0}, {1}, {1}, {2}}), (Counts{.duplicated = 1}));
  EXPECT_EQ(track({{0, false}, {1, false}, {1, false}, {2, false}}), (Counts{.duplicated = 1}));
}

TEST(SequenceTracker, DuplicateOfAnOlderFrameIsStillADuplicate) {
  EXPECT_EQ(track({{0}, {1}, {2}, {3}, {1}}), (Counts{.duplicated = 1}));
}

TEST(SequenceTracker, SwappedFramesAreOneReorderAndNoLoss) {
  EXPECT_EQ(track({{0}, {2}, {1}, {3}}), (Counts{.reordered = 1}));
  EXPECT_EQ(track({{0, false}, {2, false}, {1, false}, {3, false}}), (Counts{.reordered = 1}));
}

TEST(SequenceTracker, LateFrameArrivingTwiceIsReorderedThenDuplicated) {
  EXPECT_EQ(track({{0}, {2}, {1}, {1}}), (Counts{.duplicated = 1, .reordered = 1}));
}

TEST(SequenceTracker, WithoutTimeABurstLossIsCountedModuloSixteen) {
  EXPECT_EQ(track({{0, false}, {10, false}, {11, false}}), (Counts{.lost = 9}));
  EXPECT_EQ(track({{0, false}, {26, false}, {27, false}}), (Counts{.lost = 9}));  // 16 more are invisible
}

TEST(SequenceTracker, WithoutTimeLateFramesUpToSevenBehindAreReordered) {
  for (std::uint64_t late = 1; late <= 7; ++late) {
    std::vector<Sent> arrivals = {{0, false}};
    for (std::uint64_t i = 1; i <= late + 1; ++i)
      if (i != 1) arrivals.push_back({i, false});
    arrivals.push_back({1, false});
    EXPECT_EQ(track(arrivals), (Counts{.reordered = 1})) << "late by " << late;
  }
}

TEST(SequenceTracker, WithTimeGapsUpToSixteenAreCountedExactly) {
  for (std::uint64_t gap = 1; gap <= 16; ++gap)
    EXPECT_EQ(track({{0}, {gap}, {gap + 1}}).lost, gap - 1) << "gap " << gap;
}

TEST(SequenceTracker, WithTimeLateFramesUpToSixteenBehindAreReordered) {
  for (std::uint64_t late = 1; late <= 15; ++late) {
    std::vector<Sent> arrivals = {{0}};
    for (std::uint64_t i = 1; i <= 16; ++i)
      if (i != late) arrivals.push_back({i});
    arrivals.push_back({late});
    EXPECT_EQ(track(arrivals), (Counts{.reordered = 1})) << "late " << late;
  }
}

TEST(SequenceTracker, SharedMillisecondAboveOneKilohertzLeavesOrderToThePacketNumber) {
  // Two frames per millisecond: times 0,0,1,1,2,2...
  SequenceTracker tracker;
  for (std::uint64_t i = 0; i < 100; ++i) tracker.observe(static_cast<std::uint8_t>(i % 16), i / 2);
  EXPECT_EQ(tracker.counts(), Counts{});
  tracker.observe(99 % 16, 49);  // the last one again
  EXPECT_EQ(tracker.counts(), (Counts{.duplicated = 1}));
}

TEST(SequenceTracker, PauseWithTimeRunningOnIsNoLoss) {
  SequenceTracker tracker;
  tracker.observe(0, 1000);
  tracker.observe(1, 1001);
  tracker.observe(2, 4000);  // three seconds of silence, then the next packet number
  EXPECT_EQ(tracker.counts(), Counts{});
}

TEST(SequenceTracker, TimeGoingBackBeyondTheThresholdIsARestart) {
  SequenceTracker tracker(100);
  for (std::uint8_t i = 0; i < 40; ++i) tracker.observe(i % 16, 10'000 + i);
  // The robot reboots: time and packet number from 0.
  for (std::uint8_t i = 0; i < 40; ++i) tracker.observe(i % 16, i);
  EXPECT_EQ(tracker.counts(), (Counts{.restarts = 1}));
}

TEST(SequenceTracker, TimeGoingBackWithinTheThresholdIsReordering) {
  SequenceTracker tracker(100);
  tracker.observe(0, 1000);
  tracker.observe(2, 1002);
  tracker.observe(1, 1001);
  EXPECT_EQ(tracker.counts(), (Counts{.reordered = 1}));
}

TEST(SequenceTracker, LossAfterRestartIsCountedInTheNewSequence) {
  SequenceTracker tracker(100);
  tracker.observe(5, 90'000);
  tracker.observe(0, 0);
  tracker.observe(3, 3);
  EXPECT_EQ(tracker.counts(), (Counts{.lost = 2, .restarts = 1}));
}

// The simulator's fault model: a dropped or corrupted frame uses its packet number, a duplicate is
// sent twice in a row, a reordered frame goes out right after the next one that is sent.
TEST(SequenceTracker, SimulatorFaultPatternIsCountedExactly) {
  std::vector<Sent> arrivals;
  std::uint64_t dropped_or_corrupt = 0, duplicated = 0, reordered = 0;
  std::optional<std::uint64_t> held_back;
  for (std::uint64_t i = 0; i < 5000; ++i) {
    if (i % 7 == 6 || i % 17 == 16) {
      ++dropped_or_corrupt;
      continue;
    }
    if (i % 13 == 12 && !held_back) {
      held_back = i;
      ++reordered;
      continue;
    }
    arrivals.push_back({i});
    if (i % 11 == 10) {
      arrivals.push_back({i});
      ++duplicated;
    }
    if (held_back) arrivals.push_back({*std::exchange(held_back, std::nullopt)});
  }
  const Counts counts = track(arrivals);
  EXPECT_EQ(counts.lost, dropped_or_corrupt);
  EXPECT_EQ(counts.duplicated, duplicated);
  EXPECT_EQ(counts.reordered, reordered);
  EXPECT_EQ(counts.restarts, 0U);
}

}  // namespace
}  // namespace rsg::gateway
