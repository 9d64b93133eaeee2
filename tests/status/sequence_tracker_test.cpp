#include "status/sequence_tracker.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <random>
#include <vector>

namespace rsg::status {
namespace {

using namespace std::chrono_literals;
using Counts = SequenceTracker::Counts;
using Verdict = SequenceTracker::Verdict;

// A SequenceTracker fed as the gateway feeds it: frames arrive 1 ms apart, or when the robot's
// clock says they were sent if that is later (a pause, a gap), on the arrival clock.
class Tracker {
 public:
  explicit Tracker(std::uint64_t restart_threshold_ms = 100) : tracker_(restart_threshold_ms) {}

  Verdict observe(std::uint8_t packet_number, std::optional<std::uint64_t> time_ms) {
    arrival_ =
        std::max(arrival_ + 1ms, time_ms ? SequenceTracker::Arrival{} + std::chrono::milliseconds(*time_ms)
                                         : SequenceTracker::Arrival{});
    return tracker_.observe(packet_number, time_ms, arrival_);
  }
  /// Arrival at an explicit time (ms on the arrival clock), for frames sent by someone else.
  Verdict observe_at(std::uint64_t arrival_ms, std::uint8_t packet_number,
                     std::optional<std::uint64_t> time_ms) {
    arrival_ = std::max(arrival_, SequenceTracker::Arrival{} + std::chrono::milliseconds(arrival_ms));
    return tracker_.observe(packet_number, time_ms, arrival_);
  }
  /// Nothing arrives for `silence`.
  void wait(std::chrono::milliseconds silence) { arrival_ += silence; }
  void on_invalid() { tracker_.on_invalid(); }
  bool releases_held() const { return tracker_.releases_held(); }
  const Counts& counts() const { return tracker_.counts(); }

 private:
  SequenceTracker tracker_;
  SequenceTracker::Arrival arrival_{};
};

// A frame as the robot numbers it: its index in the robot's stream gives packet number and time.
struct Sent {
  std::uint64_t index;
  bool with_time = true;
};

Counts track(const std::vector<Sent>& arrivals, std::uint64_t first_time_ms = 5000) {
  Tracker tracker;
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
  // Its time is older than the newest frame's: counted, not published.
  EXPECT_EQ(track({{0}, {1}, {2}, {3}, {1}}), (Counts{.duplicated = 1, .out_of_sequence = 1}));
}

TEST(SequenceTracker, SwappedFramesAreOneReorderAndNoLoss) {
  EXPECT_EQ(track({{0}, {2}, {1}, {3}}), (Counts{.reordered = 1, .out_of_sequence = 1}));
  EXPECT_EQ(track({{0, false}, {2, false}, {1, false}, {3, false}}), (Counts{.reordered = 1}));
}

TEST(SequenceTracker, LateFrameArrivingTwiceIsReorderedThenDuplicated) {
  EXPECT_EQ(track({{0}, {2}, {1}, {1}}), (Counts{.duplicated = 1, .reordered = 1, .out_of_sequence = 2}));
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
    EXPECT_EQ(track(arrivals), (Counts{.reordered = 1, .out_of_sequence = 1})) << "late " << late;
  }
}

TEST(SequenceTracker, SharedMillisecondAboveOneKilohertzLeavesOrderToThePacketNumber) {
  // Two frames per millisecond: times 0,0,1,1,2,2...
  Tracker tracker;
  for (std::uint64_t i = 0; i < 100; ++i) tracker.observe(static_cast<std::uint8_t>(i % 16), i / 2);
  EXPECT_EQ(tracker.counts(), Counts{});
  tracker.observe(99 % 16, 49);  // the last one again
  EXPECT_EQ(tracker.counts(), (Counts{.duplicated = 1}));
}

TEST(SequenceTracker, PauseWithTimeRunningOnIsNoLoss) {
  Tracker tracker;
  tracker.observe(0, 1000);
  tracker.observe(1, 1001);
  tracker.observe(2, 4000);  // three seconds of silence, then the next packet number
  EXPECT_EQ(tracker.counts(), Counts{});
}

// A sender descheduled for 150 ms that then sends the frames due meanwhile at once (or a switch that
// delivers them so): each frame 1 ms after the one before on the robot's clock, all arriving together.
TEST(SequenceTracker, FramesBunchedAfterAStallAreInSequence) {
  Tracker tracker;
  for (std::uint64_t i = 0; i < 100; ++i)
    ASSERT_EQ(tracker.observe_at(i, i % 16, 1000 + i), Verdict::kInSequence);
  for (std::uint64_t i = 100; i < 250; ++i)
    EXPECT_EQ(tracker.observe_at(250, i % 16, 1000 + i), Verdict::kInSequence) << "frame " << i;
  EXPECT_EQ(tracker.counts(), Counts{});
}

TEST(SequenceTracker, ARobotRebootingAfterAPauseIsARestartAtOnce) {
  Tracker tracker(100);
  for (std::uint8_t i = 0; i < 40; ++i) tracker.observe(i % 16, 10'000 + i);
  tracker.wait(2000ms);  // the robot reboots: time and packet number from 0
  // Its first frame is held until the second confirms the new sequence; then both are published.
  EXPECT_EQ(tracker.observe(0, 0), Verdict::kHeld);
  EXPECT_EQ(tracker.observe(1, 1), Verdict::kInSequence);
  EXPECT_TRUE(tracker.releases_held());
  for (std::uint8_t i = 2; i < 40; ++i) EXPECT_EQ(tracker.observe(i % 16, i), Verdict::kInSequence);
  EXPECT_EQ(tracker.counts(), (Counts{.restarts = 1}));
}

// Without a pause the old stream could still be alive (the new one a replay): the new sequence is
// believed once the old one has been silent for the silence limit (10 ms by default).
TEST(SequenceTracker, ARestartWithoutAPauseIsBelievedOnceTheOldStreamIsSilent) {
  Tracker tracker(100);
  for (std::uint8_t i = 0; i < 40; ++i) tracker.observe(i % 16, 10'000 + i);
  std::vector<Verdict> verdicts;
  for (std::uint8_t i = 0; i < 40; ++i) verdicts.push_back(tracker.observe(i % 16, i));
  const std::vector<Verdict> expected_start(9, Verdict::kHeld);
  EXPECT_EQ(std::vector<Verdict>(verdicts.begin(), verdicts.begin() + 9), expected_start);
  EXPECT_EQ(std::count(verdicts.begin() + 9, verdicts.end(), Verdict::kInSequence), 31);
  // The 10th frame confirms the restart and releases the 9th: 8 were not published.
  EXPECT_EQ(tracker.counts(), (Counts{.restarts = 1, .out_of_sequence = 8}));
}

// A robot whose selection carries `time` only in some frames (views.churn's stream: every 10th)
// restarts after a pause: its frames without time must not keep the old stream alive, or none of
// its frames with time would ever be published again.
std::optional<std::uint64_t> every_tenth_has_time(std::uint64_t base_ms, std::uint64_t i) {
  return i % 10 == 0 ? std::optional<std::uint64_t>(base_ms + i) : std::nullopt;
}

TEST(SequenceTracker, AMixedStreamRestartedWithTimeInItsFirstFrameIsARestart) {
  Tracker tracker(100);
  for (std::uint64_t i = 0; i < 400; ++i)
    tracker.observe(static_cast<std::uint8_t>(i % 16), every_tenth_has_time(50'000, i));
  tracker.wait(2000ms);
  EXPECT_EQ(tracker.observe(0, 0), Verdict::kHeld);
  EXPECT_EQ(tracker.observe(1, std::nullopt), Verdict::kInSequence);  // goes on from the held frame
  EXPECT_TRUE(tracker.releases_held());
  for (std::uint64_t i = 2; i < 400; ++i)
    EXPECT_EQ(tracker.observe(static_cast<std::uint8_t>(i % 16), every_tenth_has_time(0, i)),
              Verdict::kInSequence)
        << "frame " << i;
  EXPECT_EQ(tracker.counts(), (Counts{.restarts = 1}));
}

TEST(SequenceTracker, AMixedStreamRestartedWithoutTimeInItsFirstFramesIsARestart) {
  Tracker tracker(100);
  for (std::uint64_t i = 0; i < 400; ++i)
    tracker.observe(static_cast<std::uint8_t>(i % 16), every_tenth_has_time(50'000, i));
  tracker.wait(2000ms);
  std::vector<Verdict> verdicts;
  for (std::uint64_t i = 1; i < 400; ++i)  // the first frame with time is the 10th
    verdicts.push_back(tracker.observe(static_cast<std::uint8_t>(i % 16), every_tenth_has_time(0, i)));
  EXPECT_EQ(verdicts[9], Verdict::kHeld);  // frame 10: its time went back while the old stream was silent
  EXPECT_EQ(std::count(verdicts.begin(), verdicts.end(), Verdict::kInSequence), 398);
  EXPECT_EQ(tracker.counts().restarts, 1U);
  EXPECT_EQ(tracker.counts().out_of_sequence, 0U);
}

// While the robot's frames with time keep coming, a frame without time after a replayed one is
// the robot's: the replay is no restart.
TEST(SequenceTracker, AFrameWithoutTimeAfterAReplayedOneIsNoRestartWhileTheStreamIsHeard) {
  Tracker tracker(100);
  for (std::uint64_t i = 0; i < 400; ++i)
    tracker.observe_at(i, static_cast<std::uint8_t>(i % 16), 50'000 + i);
  EXPECT_EQ(tracker.observe_at(400, 3, 1000), Verdict::kHeld);
  EXPECT_EQ(tracker.observe_at(401, 4, std::nullopt), Verdict::kInSequence);
  EXPECT_FALSE(tracker.releases_held());
  EXPECT_EQ(tracker.counts().restarts, 0U);
  EXPECT_EQ(tracker.counts().out_of_sequence, 1U);
}

// Frames lost while the new sequence waits for the old one's silence are lost in the new sequence.
TEST(SequenceTracker, LossesWhileARestartIsConfirmedCountInTheNewSequence) {
  Tracker tracker(100);
  for (std::uint8_t i = 0; i < 40; ++i) tracker.observe(i % 16, 10'000 + i);
  for (std::uint8_t i = 0; i < 40; ++i)
    if (i != 3) tracker.observe(i % 16, i);
  EXPECT_EQ(tracker.counts(), (Counts{.lost = 1, .restarts = 1, .out_of_sequence = 8}));
}

// A robot restarted soon after its start: its new times are below the old ones by less than the
// threshold, yet after the old stream's silence they start a new sequence, not late frames.
TEST(SequenceTracker, ARobotRestartedSoonAfterItsStartIsARestart) {
  Tracker tracker(100);
  for (std::uint64_t i = 0; i < 50; ++i) tracker.observe_at(i, static_cast<std::uint8_t>(i % 16), i);
  EXPECT_EQ(tracker.observe_at(200, 0, 0), Verdict::kHeld);
  EXPECT_EQ(tracker.observe_at(201, 1, 1), Verdict::kInSequence);
  EXPECT_TRUE(tracker.releases_held());
  EXPECT_EQ(tracker.counts(), (Counts{.restarts = 1}));
}

TEST(SequenceTracker, TimeGoingBackWithinTheThresholdIsReorderingAndNotPublished) {
  Tracker tracker(100);
  EXPECT_EQ(tracker.observe(0, 1000), Verdict::kInSequence);
  EXPECT_EQ(tracker.observe(2, 1002), Verdict::kInSequence);
  EXPECT_EQ(tracker.observe(1, 1001), Verdict::kOutOfSequence);
  EXPECT_EQ(tracker.counts(), (Counts{.reordered = 1, .out_of_sequence = 1}));
}

TEST(SequenceTracker, LossAfterRestartIsCountedInTheNewSequence) {
  Tracker tracker(100);
  tracker.observe(5, 90'000);
  tracker.wait(3000ms);
  tracker.observe(0, 0);
  tracker.observe(3, 3);
  EXPECT_EQ(tracker.counts(), (Counts{.lost = 2, .restarts = 1}));
}

// Issue 39: 100 replayed frames read "lost +400, robot_restarts +100". Frames from a capture,
// sent again between the robot's own, are neither a restart nor a gap in the robot's stream.
TEST(SequenceTracker, ReplayedFramesInterleavedWithTheStreamAreOnlyOutOfSequence) {
  Tracker tracker(100);
  for (std::uint64_t i = 0; i < 1000; ++i) tracker.observe(static_cast<std::uint8_t>(i % 16), 5000 + i);
  for (std::uint64_t i = 0; i < 100; ++i) {
    EXPECT_EQ(tracker.observe(static_cast<std::uint8_t>(i % 16), 5000 + i), Verdict::kHeld);
    const std::uint64_t next = 1000 + i;
    EXPECT_EQ(tracker.observe(static_cast<std::uint8_t>(next % 16), 5000 + next), Verdict::kInSequence);
  }
  EXPECT_EQ(tracker.counts(), (Counts{.out_of_sequence = 100}));
}

// Issue 39: 1,000 forged frames interleaved read "lost +9,000, robot_restarts +999". Forged frames
// with any packet number and a time in the past, or further ahead than the arrival clock ran.
TEST(SequenceTracker, ForgedFramesInterleavedWithTheStreamAreOnlyOutOfSequence) {
  Tracker tracker(100);
  std::mt19937_64 random(39);
  // The robot's frame i arrives at i ms, a forged one right before it.
  for (std::uint64_t i = 0; i < 200; ++i) tracker.observe_at(i, static_cast<std::uint8_t>(i % 16), 5000 + i);
  for (std::uint64_t i = 200; i < 1200; ++i) {
    const std::uint64_t newest = 5000 + i - 1;
    const std::uint64_t forged_time =
        random() % 2 ? random() % (newest - 100) : newest + 1000 + random() % 1'000'000;
    EXPECT_EQ(tracker.observe_at(i - 1, static_cast<std::uint8_t>(random() % 16), forged_time),
              Verdict::kHeld)
        << "forged time " << forged_time << " after " << newest;
    EXPECT_EQ(tracker.observe_at(i, static_cast<std::uint8_t>(i % 16), 5000 + i), Verdict::kInSequence);
  }
  EXPECT_EQ(tracker.counts(), (Counts{.out_of_sequence = 1000}));
}

// A frame whose time is further ahead than the arrival clock (plus the 10 ms allowance) ran since
// the newest one cannot be the robot's next frame: the stream goes on without it.
TEST(SequenceTracker, AFrameFromTheFutureIsOutOfSequenceWhileTheStreamGoesOn) {
  Tracker tracker(100);
  tracker.observe_at(0, 0, 5000);
  EXPECT_EQ(tracker.observe_at(1, 1, 5030), Verdict::kHeld);  // 30 ms of time in 1 ms
  EXPECT_EQ(tracker.observe_at(1, 1, 5001), Verdict::kInSequence);
  EXPECT_EQ(tracker.observe_at(500, 2, 5500), Verdict::kInSequence);  // a pause: both clocks ran
  EXPECT_EQ(tracker.counts(), (Counts{.out_of_sequence = 1}));
}

// A new sequence while the stream has been silent that long is believed once it goes on: only a
// sender who outlasts the robot's own silence can fake a restart.
TEST(SequenceTracker, AnotherSequenceAfterTheSilenceLimitIsARestart) {
  Tracker tracker(100);
  tracker.observe_at(0, 0, 5000);
  EXPECT_EQ(tracker.observe_at(9, 1, 100), Verdict::kHeld);
  EXPECT_EQ(tracker.observe_at(10, 2, 101), Verdict::kInSequence);
  EXPECT_TRUE(tracker.releases_held());
  EXPECT_EQ(tracker.counts(), (Counts{.restarts = 1}));
}

// The robot stalls for longer than the silence limit while a forger sends one frame: it is not
// taken for a restart, and the robot's next frame continues the stream.
TEST(SequenceTracker, AFrameOfAnotherSequenceInTheRobotsSilenceIsNoRestart) {
  Tracker tracker(100);
  tracker.observe_at(0, 0, 5000);
  EXPECT_EQ(tracker.observe_at(20, 7, 300), Verdict::kHeld);
  EXPECT_EQ(tracker.observe_at(21, 1, 5021), Verdict::kInSequence);
  EXPECT_FALSE(tracker.releases_held());
  EXPECT_EQ(tracker.counts(), (Counts{.out_of_sequence = 1}));
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
  Tracker tracker;
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
  Tracker tracker;
  tracker.observe(0, 5000);
  tracker.on_invalid();  // frame 1 arrived corrupted; frames 2 and 3 never arrived
  tracker.observe(4, 5004);
  EXPECT_EQ(tracker.counts(), (Counts{.lost = 2}));
  tracker.observe(2, 5002);  // one of the lost ones arrives late after all
  EXPECT_EQ(tracker.counts(), (Counts{.lost = 1, .reordered = 1, .out_of_sequence = 1}));
}

// The simulator holds frame 4 back and sends it after the next one, which it corrupts: the gap
// the invalid frame leaves shows only when frame 6 arrives.
TEST(SequenceTracker, AnInvalidFrameFillsTheGapItLeavesEvenWhenThatShowsLater) {
  Tracker tracker;
  tracker.observe(3, 5003);
  tracker.on_invalid();      // 5, corrupted
  tracker.observe(4, 5004);  // 4, held back: in order after 3
  tracker.observe(6, 5006);  // the gap at 5
  EXPECT_EQ(tracker.counts(), Counts{});
}

// The simulator releases a held-back frame only behind a valid one: 4 held, 5 corrupted, then 6, 4.
TEST(SequenceTracker, AFrameHeldBackBehindAnInvalidOneIsReorderedNotDuplicated) {
  Tracker tracker;
  tracker.observe(3, 5003);
  tracker.on_invalid();      // 5
  tracker.observe(6, 5006);  // 4 and 5 skipped; the invalid one covers one of them
  tracker.observe(4, 5004);  // late
  tracker.observe(7, 5007);
  EXPECT_EQ(tracker.counts(), (Counts{.reordered = 1, .out_of_sequence = 1}));
  // And without time, where only the packet number places a frame.
  Tracker untimed;
  untimed.observe(3, std::nullopt);
  untimed.on_invalid();
  untimed.observe(6, std::nullopt);
  untimed.observe(4, std::nullopt);
  untimed.observe(7, std::nullopt);
  EXPECT_EQ(untimed.counts(), (Counts{.reordered = 1}));
}

// The simulator's fault model with corruption: a corrupted frame is sent in place of the valid one.
TEST(SequenceTracker, SimulatorFaultPatternWithCorruptionCountsOnlyDropsAsLost) {
  Tracker tracker;
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
  EXPECT_EQ(
      tracker.counts(),
      (Counts{
          .lost = dropped, .duplicated = duplicated, .reordered = reordered, .out_of_sequence = reordered}));
}

TEST(SequenceTracker, AnInvalidDatagramThatFillsNoGapSoonIsForgotten) {
  Tracker tracker;
  tracker.observe(0, 5000);
  tracker.on_invalid();  // not one of the robot's frames: no gap follows
  for (std::uint64_t i = 1; i <= 17; ++i) tracker.observe(static_cast<std::uint8_t>(i % 16), 5000 + i);
  tracker.observe(19 % 16, 5019);  // a real loss, 17 frames later, is still counted
  EXPECT_EQ(tracker.counts(), (Counts{.lost = 1}));
}

TEST(SequenceTracker, InvalidFramesBeforeTheFirstValidOneCountNothing) {
  Tracker tracker;
  tracker.on_invalid();
  tracker.on_invalid();
  tracker.observe(9, 5000);
  tracker.observe(11, 5002);
  EXPECT_EQ(tracker.counts(), (Counts{.lost = 1}));
}

}  // namespace
}  // namespace rsg::status
