#include "gateway/no_link_warning.hpp"

#include <gtest/gtest.h>

namespace rsg::gateway {
namespace {

using std::chrono::seconds;
const Clock::time_point kGatewayStart{seconds(1000)};

TEST(NoLinkWarning, SaysOnceAfterTenSecondsThatNoDatagramArrived) {
  NoLinkWarning warning("0.0.0.0:17000", kGatewayStart);
  const status::GatewayStats silent;
  EXPECT_FALSE(warning.due(silent, kGatewayStart + seconds(9)));
  const auto said = warning.due(silent, kGatewayStart + seconds(10));
  ASSERT_TRUE(said);
  EXPECT_EQ(*said,
            "no datagram on 0.0.0.0:17000 for 10 s: is the robot sending here (its destination address and "
            "port), and does no firewall drop it?");
  EXPECT_FALSE(warning.due(silent, kGatewayStart + seconds(20)));
}

TEST(NoLinkWarning, DatagramsThatAreNoFramesAreCountedByCategory) {
  NoLinkWarning warning("127.0.0.1:17000", kGatewayStart);
  status::GatewayStats stats;
  stats.ingress.received = 12;
  stats.ingress.invalid[status::invalid_index(wire::ErrorCategory::kBadCrc)] = 10;
  stats.ingress.invalid[status::invalid_index(wire::ErrorCategory::kLengthMismatch)] = 2;
  const auto said = warning.due(stats, kGatewayStart + seconds(11));
  ASSERT_TRUE(said);
  EXPECT_EQ(
      *said,
      "no valid frame on 127.0.0.1:17000 for 11 s: 12 datagrams arrived, every one rejected "
      "(length_mismatch=2 bad_crc=10): is the robot sending SEND_BUF frames as docs/protocol.md defines "
      "them? (rsg_frame decode shows why one fails)");
}

TEST(NoLinkWarning, DatagramsFromOutsideAllowFromAreNamedAsSuch) {
  NoLinkWarning warning("127.0.0.1:17000", kGatewayStart);
  status::GatewayStats stats;
  stats.ingress.rejected_source = 7;
  const auto said = warning.due(stats, kGatewayStart + seconds(10));
  ASSERT_TRUE(said);
  EXPECT_NE(said->find("7 came from outside --allow-from"), std::string::npos) << *said;
}

TEST(NoLinkWarning, NeverSaysAnythingOnceAFrameWasValid) {
  NoLinkWarning warning("127.0.0.1:17000", kGatewayStart);
  status::GatewayStats stats;
  stats.ingress.received = 1;
  stats.ingress.published = 1;
  EXPECT_FALSE(warning.due(stats, kGatewayStart + seconds(1)));
  EXPECT_FALSE(
      warning.due(status::GatewayStats{}, kGatewayStart + seconds(60)));  // a link that went down later
}

}  // namespace
}  // namespace rsg::gateway
