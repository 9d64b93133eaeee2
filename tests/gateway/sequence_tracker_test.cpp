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

// Issue 30: 8 corrupted frames read "lost 8" although the simulator dropped none.
TEST(SequenceTracker, InvalidFramesAreNotAlsoCountedAsLost) {
  SequenceTracker tracker;
  for (std::uint64_t i = 0; i < 100; ++i) {
    if (i % 12 == 5) {  // rejected by the decoder: reported to the tracker, not observed
      tracker.on_invalid();
      continue;
    }
    tracker.observe(static_cast<std::uint8_t>(i % 16), 5000 + i);
  }
  EXPECT_EQ(tracker.counts(), Counts{});
}

TEST(SequenceTracker, AGapLongerThanTheInvalidFramesIsStillLost) {
  SequenceTracker tracker;
  tracker.observe(0, 5000);
  tracker.on_invalid();  // frame 1 arrived corrupted; frames 2 and 3 never arrived
  tracker.observe(4, 5004);
  EXPECT_EQ(tracker.counts(), (Counts{.lost = 2}));
  tracker.observe(2, 5002);  // one of the lost ones arrives late after all
  EXPECT_EQ(tracker.counts(), (Counts{.lost = 1, .reordered = 1}));
}

// The simulator holds frame 4 back and sends it after the next one, which it corrupts: the gap
// the invalid frame leaves shows only when frame 6 arrives.
TEST(SequenceTracker, AnInvalidFrameFillsTheGapItLeavesEvenWhenThatShowsLater) {
  SequenceTracker tracker;
  tracker.observe(3, 5003);
  tracker.on_invalid();      // 5, corrupted
  tracker.observe(4, 5004);  // 4, held back: in order after 3
  tracker.observe(6, 5006);  // the gap at 5
  EXPECT_EQ(tracker.counts(), Counts{});
}

// The simulator releases a held-back frame only behind a valid one: 4 held, 5 corrupted, then 6, 4.
TEST(SequenceTracker, AFrameHeldBackBehindAnInvalidOneIsReorderedNotDuplicated) {
  SequenceTracker tracker;
  tracker.observe(3, 5003);
  tracker.on_invalid();      // 5
  tracker.observe(6, 5006);  // 4 and 5 skipped; the invalid one covers one of them
  tracker.observe(4, 5004);  // late
  tracker.observe(7, 5007);
  EXPECT_EQ(tracker.counts(), (Counts{.reordered = 1}));
  // And without time, where only the packet number places a frame.
  SequenceTracker untimed;
  untimed.observe(3, std::nullopt);
  untimed.on_invalid();
  untimed.observe(6, std::nullopt);
  untimed.observe(4, std::nullopt);
  untimed.observe(7, std::nullopt);
  EXPECT_EQ(untimed.counts(), (Counts{.reordered = 1}));
}

// The simulator's fault model with corruption: a corrupted frame is sent in place of the valid one.
TEST(SequenceTracker, SimulatorFaultPatternWithCorruptionCountsOnlyDropsAsLost) {
  SequenceTracker tracker;
  std::uint64_t dropped = 0, duplicated = 0, reordered = 0;
  std::optional<std::uint64_t> held_back;
  const auto send = [&](std::uint64_t i) { tracker.observe(static_cast<std::uint8_t>(i % 16), 5000 + i); };
  for (std::uint64_t i = 0; i < 5000; ++i) {
    if (i % 7 == 6) {
      ++dropped;
      continue;
    }
    if (i % 17 == 16) {
      tracker.on_invalid();
      continue;
    }
    if (i % 13 == 12 && !held_back) {
      held_back = i;
      ++reordered;
      continue;
    }
    send(i);
    if (i % 11 == 10) {
      send(i);
      ++duplicated;
    }
    if (held_back) send(*std::exchange(held_back, std::nullopt));
  }
  EXPECT_EQ(tracker.counts(), (Counts{.lost = dropped, .duplicated = duplicated, .reordered = reordered}));
}

TEST(SequenceTracker, AnInvalidDatagramThatFillsNoGapSoonIsForgotten) {
  SequenceTracker tracker;
  tracker.observe(0, 5000);
  tracker.on_invalid();  // not one of the robot's frames: no gap follows
  for (std::uint64_t i = 1; i <= 17; ++i) tracker.observe(static_cast<std::uint8_t>(i % 16), 5000 + i);
  tracker.observe(19 % 16, 5019);  // a real loss, 17 frames later, is still counted
  EXPECT_EQ(tracker.counts(), (Counts{.lost = 1}));
}

TEST(SequenceTracker, InvalidFramesBeforeTheFirstValidOneCountNothing) {
  SequenceTracker tracker;
  tracker.on_invalid();
  tracker.on_invalid();
  tracker.observe(9, 5000);
  tracker.observe(11, 5002);
  EXPECT_EQ(tracker.counts(), (Counts{.lost = 1}));
}

}  // namespace
}  // namespace rsg::gateway
