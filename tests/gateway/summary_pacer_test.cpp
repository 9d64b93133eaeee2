// When the gateway logs its summary line (src/gateway/log_throttle.hpp): every 10 s while the
// counters move, once an hour while nothing changes.
#include <gtest/gtest.h>

#include "gateway/log_throttle.hpp"

namespace rsg::gateway {
namespace {

using std::chrono::hours;
using std::chrono::seconds;

TEST(SummaryPacer, AnIdleGatewayLogsItsUnchangedSummaryOnceAnHour) {
  const auto start = Clock::now();
  SummaryPacer pacer(start);
  const std::string idle = "link down from (nobody yet) at 0.0 Hz; received 0 published 0";
  int logged = 0;
  // A day of status periods, one a second.
  for (auto now = start + seconds(1); now <= start + hours(24); now += seconds(1))
    if (pacer.may_log(now) && pacer.due(idle, now)) ++logged;
  EXPECT_EQ(logged, 24);  // the first at 10 s, then one an hour (not 8640)
}

TEST(SummaryPacer, AChangingSummaryIsLoggedEveryTenSeconds) {
  const auto start = Clock::now();
  SummaryPacer pacer(start);
  int logged = 0;
  int published = 0;
  for (auto now = start + seconds(1); now <= start + seconds(60); now += seconds(1)) {
    published += 1000;
    if (pacer.may_log(now) && pacer.due("published " + std::to_string(published), now)) ++logged;
  }
  EXPECT_EQ(logged, 6);
}

TEST(SummaryPacer, AChangeAfterALongIdleIsLoggedAtItsNextTenSecondTurn) {
  const auto start = Clock::now();
  SummaryPacer pacer(start);
  EXPECT_FALSE(pacer.may_log(start + seconds(9)));
  EXPECT_TRUE(pacer.due("idle", start + seconds(10)));
  EXPECT_FALSE(pacer.due("idle", start + seconds(20)));
  EXPECT_FALSE(pacer.due("idle", start + seconds(600)));
  EXPECT_FALSE(pacer.due("link up", start + seconds(605))) << "within 10 s of the last look";
  EXPECT_TRUE(pacer.due("link up", start + seconds(610)));
  EXPECT_FALSE(pacer.due("link up", start + seconds(620)));
}

}  // namespace
}  // namespace rsg::gateway
