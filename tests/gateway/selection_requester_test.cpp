// What the gateway says about its selection requests (the timing is in link_monitor_test.cpp).
#include "gateway/selection_requester.hpp"

#include <gtest/gtest.h>

#include "tests/support/captured_log.hpp"

namespace rsg::gateway {
namespace {

using std::chrono::seconds;
const Clock::time_point kFirstRequest = Clock::time_point() + std::chrono::hours(1);

wire::Selection group(std::size_t g) {
  wire::Selection selection;
  selection.group_select = static_cast<std::uint8_t>(1U << g);
  selection.data_select[g] = 0xFF;
  return selection;
}

std::size_t occurrences(const std::string& text, const std::string& what) {
  std::size_t count = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++count;
  return count;
}

TEST(SelectionRequester, AfterThreeUnansweredRequestsWarnsOnceAndAsksEveryTenSeconds) {
  const test::CapturedLog log;
  SelectionRequester requester(group(2));
  const wire::Selection all = wire::Selection::all();
  int sent = 0;
  // Frames with the robot's default every 100 ms for a minute; the robot never switches.
  std::vector<int> sent_at_second;
  for (int tenth = 0; tenth < 600; ++tenth) {
    const auto now = kFirstRequest + std::chrono::milliseconds(100 * tenth);
    if (requester.due(all, now)) {
      ++sent;
      sent_at_second.push_back(tenth / 10);
      requester.log_sent("127.0.0.1:17001", "127.0.0.1:40000");
    }
  }
  // Three a second apart, then one every 10 s: 0, 1, 2, 3, 13, 23, 33, 43, 53.
  EXPECT_EQ(sent_at_second, (std::vector<int>{0, 1, 2, 3, 13, 23, 33, 43, 53}));
  EXPECT_EQ(occurrences(log.text(), "asked 127.0.0.1:17001 for selection group_select=0x04"), 3u)
      << log.text();
  EXPECT_EQ(occurrences(log.text(), "went unanswered"), 1u);
  EXPECT_NE(
      log.text().find("3 selection requests to 127.0.0.1:17001 went unanswered: the frames from "
                      "127.0.0.1:40000 still carry group_select=0x3f, not 0x04. A robot takes requests on "
                      "the port it streams from unless --robot names another: is that where it listens? "
                      "Asking every 10 s from now on"),
      std::string::npos)
      << log.text();
  EXPECT_EQ(requester.unanswered(), static_cast<unsigned>(sent));
}

TEST(SelectionRequester, AnAnswerAfterTheWarningIsSaidAndRestoresTheFastPace) {
  SelectionRequester requester(group(2));
  const wire::Selection all = wire::Selection::all();
  for (int s = 0; s < 4; ++s) ASSERT_TRUE(requester.due(all, kFirstRequest + seconds(s)));
  const test::CapturedLog log;
  EXPECT_FALSE(requester.due(group(2), kFirstRequest + seconds(5)));
  EXPECT_NE(
      log.text().find("the robot streams the requested selection group_select=0x04 now, after 4 requests"),
      std::string::npos)
      << log.text();
  EXPECT_EQ(requester.unanswered(), 0u);
  // The robot restarts with its default: asked again at once, then a second later.
  EXPECT_TRUE(requester.due(all, kFirstRequest + seconds(7)));
  EXPECT_TRUE(requester.due(all, kFirstRequest + seconds(8)));
}

}  // namespace
}  // namespace rsg::gateway
