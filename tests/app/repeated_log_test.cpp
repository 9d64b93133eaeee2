// The one pacing of repeated log lines (src/app/repeated_log.hpp): the first line at once, then one
// line a minute with the count of what came between, and nothing allocated on the way (it sits on
// the gateway's ingress path, tests/gateway/ingress_alloc_test.cpp's hot path).
#include "app/repeated_log.hpp"

#include <gtest/gtest.h>

#include "tests/support/allocation_counter.hpp"

namespace rsg::app {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
const RepeatedLog::Clock::time_point kT0 = RepeatedLog::Clock::time_point() + std::chrono::hours(1);

TEST(RepeatedLog, TheFirstEventIsLoggedAtOnceThenOneCountAMinute) {
  RepeatedLog log;
  EXPECT_EQ(log.take(kT0), 1U);  // at once
  // A flood: 1,000 events a second for two minutes, and the periodic check of every second.
  std::uint64_t lines = 1, logged = 1;
  for (int ms = 1; ms < 120'000; ++ms) {
    if (const auto n = log.take(kT0 + milliseconds(ms))) {
      ++lines;
      logged += n;
    }
    if (ms % 1000 == 0)
      if (const auto n = log.take(kT0 + milliseconds(ms), 0)) {
        ++lines;
        logged += n;
      }
  }
  EXPECT_EQ(lines, 2U);  // the first, and one at the minute; the second minute's count is held
  EXPECT_EQ(log.take(kT0 + seconds(120), 0) + logged, log.total());
  EXPECT_EQ(log.held(), 0U);
}

TEST(RepeatedLog, AnEventAfterAQuietMinuteIsLoggedAtOnce) {
  RepeatedLog log;
  EXPECT_EQ(log.take(kT0), 1U);
  EXPECT_EQ(log.take(kT0 + seconds(10)), 0U);
  EXPECT_EQ(log.take(kT0 + seconds(60), 0), 1U);  // the held one, counted
  EXPECT_EQ(log.take(kT0 + seconds(200)), 1U);    // quiet since: at once
  EXPECT_EQ(log.take(kT0 + seconds(201), 0), 0U);
}

TEST(RepeatedLog, NoEventsNoLine) {
  RepeatedLog log;
  EXPECT_EQ(log.take(kT0, 0), 0U);
  EXPECT_EQ(log.take(kT0 + seconds(600), 0), 0U);
  EXPECT_EQ(log.take(kT0 + seconds(601), 5), 5U);  // several at once: one line for them
}

TEST(RepeatedLog, AllocatesNothing) {
  RepeatedLog log(seconds(1));
  test::AllocationCounter allocations;
  allocations.resume();
  std::uint64_t sum = 0;
  for (int ms = 0; ms < 10'000; ++ms) sum += log.take(kT0 + milliseconds(ms), ms % 3);
  allocations.pause();
  EXPECT_EQ(allocations.total(), 0U);
  EXPECT_EQ(sum + log.held(), log.total());
}

}  // namespace
}  // namespace rsg::app
