#include "gateway/decimator.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace rsg::gateway {
namespace {

using std::chrono::milliseconds;
using std::chrono::nanoseconds;

// The frame times (ms) a decimator takes out of `times`.
std::vector<long> taken(Decimation decimation, const std::vector<long>& times) {
  Decimator decimator(decimation);
  std::vector<long> out;
  for (const long t : times)
    if (decimator.due(milliseconds(t))) out.push_back(t);
  return out;
}

std::vector<long> every_ms(long from, long to, long step = 1) {
  std::vector<long> times;
  for (long t = from; t < to; t += step) times.push_back(t);
  return times;
}

TEST(Decimator, EveryNthTakesTheFirstFrameAndEachNthAfterIt) {
  EXPECT_EQ(taken({3, {}}, every_ms(0, 10)), (std::vector<long>{0, 3, 6, 9}));
  EXPECT_EQ(taken({1, {}}, every_ms(0, 4)), (std::vector<long>{0, 1, 2, 3}));
  // Counting frames, not time: a time that jumps or repeats changes nothing.
  EXPECT_EQ(taken({2, {}}, {5, 5, 5, 1000, 0, 7}), (std::vector<long>{5, 5, 0}));
}

TEST(Decimator, APeriodTakesOneFramePerPeriodOnTheRobotsSchedule) {
  // 1 kHz at 100 Hz: frames 0, 10, 20, ... whatever the phase of the first.
  EXPECT_EQ(taken({0, milliseconds(10)}, every_ms(3, 45)), (std::vector<long>{3, 13, 23, 33, 43}));
  // Frames 3 ms apart at a 10 ms period: the schedule keeps its 10 ms grid (due at 10, 20, 30, 40),
  // so the takes are the first frames at or after each due time, not 10 ms after the last take
  // (which would give 0, 12, 24, 36).
  EXPECT_EQ(taken({0, milliseconds(10)}, every_ms(0, 40, 3)), (std::vector<long>{0, 12, 21, 30}));
}

TEST(Decimator, AStallOrARestartedRobotRestartsTheScheduleInsteadOfCatchingUp) {
  // After a 100 ms gap one frame is taken, not the ten that were "missed".
  EXPECT_EQ(taken({0, milliseconds(10)}, {0, 10, 110, 111, 115, 120}), (std::vector<long>{0, 10, 110, 120}));
  // Time going back (the robot restarted): the next frame is taken and starts a new schedule.
  EXPECT_EQ(taken({0, milliseconds(10)}, {500, 510, 0, 5, 10}), (std::vector<long>{500, 510, 0, 10}));
}

TEST(Decimator, ABurstDeliveredLateKeepsTheRobotsSpacingOnlyWhenPacedByItsTime) {
  // 20 frames of 1 ms robot time that a loaded host delivers at once: paced by their `time` they
  // give the 5 ms topic its 4 samples (why the gateway passes the frame's time when it has one);
  // paced by their common arrival time, only 1.
  EXPECT_EQ(taken({0, milliseconds(5)}, every_ms(0, 20)), (std::vector<long>{0, 5, 10, 15}));
  EXPECT_EQ(taken({0, milliseconds(5)}, std::vector<long>(20, 100)), (std::vector<long>{100}));
}

TEST(Decimator, PeriodsBelowAMillisecondWork) {
  Decimator decimator({0, nanoseconds(250'000)});  // 4 kHz
  int takes = 0;
  for (long us = 0; us < 10'000; us += 100)
    if (decimator.due(std::chrono::microseconds(us))) ++takes;
  EXPECT_EQ(takes, 40);
}

}  // namespace
}  // namespace rsg::gateway
