// What a SIGHUP reload counts as widening access (gateway.hpp, widened_access): refused unless the
// file says reload-widens-access (integration.attack_reload runs it against a real gateway).
#include <gtest/gtest.h>

#include "gateway/gateway.hpp"

namespace rsg::gateway {
namespace {

GatewayConfig with_allow_from(std::vector<std::string> networks) {
  GatewayConfig config;
  config.listen = "127.0.0.1:17000";
  config.allow_from = std::move(networks);
  return config;
}

TEST(WidenedAccess, AnAllowFromThatDisappearsOrGrowsToEveryoneWidens) {
  const GatewayConfig running = with_allow_from({"127.0.0.1/32"});
  EXPECT_TRUE(widened_access(running, with_allow_from({})));
  EXPECT_TRUE(widened_access(running, with_allow_from({"127.0.0.1/32", "0.0.0.0/0"})));
  EXPECT_TRUE(widened_access(running, with_allow_from({"::/0"})));
  EXPECT_NE(widened_access(running, with_allow_from({}))->find("to everyone"), std::string::npos);
}

TEST(WidenedAccess, AnotherRobotsAddressOrANarrowerListDoesNot) {
  const GatewayConfig running = with_allow_from({"192.168.1.0/24"});
  EXPECT_FALSE(widened_access(running, with_allow_from({"192.168.2.0/24"})));
  EXPECT_FALSE(widened_access(running, with_allow_from({"192.168.1.7"})));
  EXPECT_FALSE(widened_access(running, running));
  EXPECT_FALSE(widened_access(with_allow_from({}), with_allow_from({})));  // open already
}

TEST(WidenedAccess, SecurityAndDataSharingChangesWiden) {
  const GatewayConfig running = with_allow_from({"127.0.0.1"});
  GatewayConfig fresh = running;
  fresh.participant_profile = "rsg_participant_plain";
  EXPECT_TRUE(widened_access(running, fresh));
  fresh = running;
  fresh.profiles = {"/tmp/elsewhere"};
  EXPECT_TRUE(widened_access(running, fresh));
  GatewayConfig closed = running;
  closed.data_sharing = "off";
  fresh = closed;
  fresh.data_sharing = "auto";
  EXPECT_TRUE(widened_access(closed, fresh));
  EXPECT_FALSE(widened_access(fresh, closed));  // off is narrower
}

}  // namespace
}  // namespace rsg::gateway
