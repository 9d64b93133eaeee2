#include "gateway/link_monitor.hpp"

#include <gtest/gtest.h>

#include "gateway/selection_requester.hpp"

namespace rsg::gateway {
namespace {

using std::chrono::milliseconds;

const Clock::time_point kStart = Clock::time_point() + std::chrono::hours(1);

TEST(LinkMonitor, DownUntilTheFirstFrame) {
  LinkMonitor link(milliseconds(1));
  EXPECT_FALSE(link.up());
  EXPECT_FALSE(link.poll(kStart));
  EXPECT_EQ(link.deadline(), Clock::time_point::max());
  EXPECT_TRUE(link.on_frame(kStart));
  EXPECT_TRUE(link.up());
}

TEST(LinkMonitor, StaysUpWhileFramesKeepComing) {
  LinkMonitor link(milliseconds(1));
  for (int i = 0; i < 1000; ++i) {
    const bool came_up = link.on_frame(kStart + milliseconds(i));
    EXPECT_EQ(came_up, i == 0);
    EXPECT_FALSE(link.poll(kStart + milliseconds(i) + milliseconds(9)));
  }
}

TEST(LinkMonitor, GoesDownOnceAfterTenSilentPeriods) {
  LinkMonitor link(milliseconds(1));
  link.on_frame(kStart);
  EXPECT_EQ(link.deadline(), kStart + milliseconds(10));
  EXPECT_FALSE(link.poll(kStart + milliseconds(9)));
  EXPECT_TRUE(link.poll(kStart + milliseconds(10)));
  EXPECT_FALSE(link.up());
  EXPECT_FALSE(link.poll(kStart + milliseconds(50)));  // reported once
  EXPECT_TRUE(link.on_frame(kStart + milliseconds(60)));
}

TEST(LinkMonitor, NeverGoesDownAfterLessThanTenMilliseconds) {
  LinkMonitor link(std::chrono::microseconds(200));  // 5 kHz: ten periods would be 2 ms
  link.on_frame(kStart);
  EXPECT_FALSE(link.poll(kStart + milliseconds(5)));
  EXPECT_TRUE(link.poll(kStart + LinkMonitor::kMinSilence));
}

TEST(LinkMonitor, SilenceLimitFollowsTheNominalRate) {
  LinkMonitor link(milliseconds(10), 10);  // 100 Hz
  link.on_frame(kStart);
  EXPECT_FALSE(link.poll(kStart + milliseconds(99)));
  EXPECT_TRUE(link.poll(kStart + milliseconds(100)));
}

TEST(RateMeter, FramesPerSecondBetweenReadings) {
  RateMeter meter;
  EXPECT_EQ(meter.update(0, kStart), 0.0);
  EXPECT_DOUBLE_EQ(meter.update(500, kStart + milliseconds(500)), 1000.0);
  EXPECT_DOUBLE_EQ(meter.update(500, kStart + milliseconds(1500)), 0.0);
}

wire::Selection groups(std::initializer_list<std::size_t> list) {
  wire::Selection selection;
  for (const std::size_t group : list) selection.add_group(group);
  return selection;
}

TEST(SelectionRequester, RequestsAtStartUpOnce) {
  SelectionRequester requester(groups({2}));
  EXPECT_TRUE(requester.start_up_due(kStart));
  EXPECT_FALSE(requester.start_up_due(kStart + std::chrono::seconds(5)));
}

TEST(SelectionRequester, RepeatsAtMostOncePerIntervalWhileFramesDiffer) {
  SelectionRequester requester(groups({2}), std::chrono::seconds(1));
  requester.start_up_due(kStart);
  EXPECT_FALSE(requester.due(groups({0, 1, 2, 3, 4, 5}), kStart + milliseconds(1)));
  EXPECT_FALSE(requester.due(groups({0, 1, 2, 3, 4, 5}), kStart + milliseconds(999)));
  EXPECT_TRUE(requester.due(groups({0, 1, 2, 3, 4, 5}), kStart + milliseconds(1000)));
  EXPECT_FALSE(requester.due(groups({0, 1, 2, 3, 4, 5}), kStart + milliseconds(1001)));
}

TEST(SelectionRequester, FramesWithTheWantedSelectionNeverTriggerARequest) {
  SelectionRequester requester(groups({2}));
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(requester.due(groups({2}), kStart + std::chrono::seconds(i)));
}

TEST(SelectionRequester, FirstDifferentFrameTriggersARequestWhenNoneWasSent) {
  // Without --robot the start-up request has no address; the first frame supplies it.
  SelectionRequester requester(groups({2}));
  EXPECT_TRUE(requester.due(groups({0}), kStart));
}

}  // namespace
}  // namespace rsg::gateway
