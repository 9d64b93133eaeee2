// The one HOST:PORT syntax that configuration, discovery and sockets share.
#include "rsg/transport/host_port.hpp"

#include <gtest/gtest.h>

namespace rsg {
namespace {

TEST(HostPort, EachRuleAcceptsWhatItNames) {
  using transport::HostPortRule;
  const auto parsed = [](std::string_view value, HostPortRule rule) {
    const wire::Parsed<transport::HostPort> result = transport::parse_host_port(value, rule);
    EXPECT_TRUE(result) << value << ": " << result.error();
    return result ? *result : transport::HostPort{};
  };
  EXPECT_EQ(parsed("robot:17000", HostPortRule::kPortRequired).host, "robot");
  EXPECT_EQ(parsed("robot:17000", HostPortRule::kPortRequired).port, 17000u);
  EXPECT_EQ(parsed("[::1]:5", HostPortRule::kPortRequired).host, "[::1]");
  EXPECT_EQ(parsed("0.0.0.0:0", HostPortRule::kPortMayBeZero).port, 0u);
  EXPECT_EQ(parsed("peer", HostPortRule::kPortOptional).host, "peer");
  EXPECT_EQ(parsed("peer", HostPortRule::kPortOptional).port, 0u);
  EXPECT_EQ(parsed(":0", HostPortRule::kBindAddress).host, "");
  EXPECT_EQ(transport::parse_peer("h:7400")->port, 7400u);
}

TEST(HostPort, BadValuesSayWhatIsWrong) {
  using transport::HostPortRule;
  const auto error = [](std::string_view value, HostPortRule rule) {
    const wire::Parsed<transport::HostPort> result = transport::parse_host_port(value, rule);
    EXPECT_FALSE(result) << value;
    return result.error();
  };
  EXPECT_EQ(error("robot", HostPortRule::kPortRequired), "'robot' is not HOST:PORT");
  EXPECT_EQ(error(":1", HostPortRule::kPortRequired), "':1' is not HOST:PORT");
  EXPECT_EQ(error("", HostPortRule::kPortOptional), "'' is not HOST:PORT");
  EXPECT_EQ(error("h:0", HostPortRule::kPortRequired), "'h:0': port must be a number 1..65535");
  EXPECT_EQ(error("h:65536", HostPortRule::kPortMayBeZero), "'h:65536': port must be a number 0..65535");
  EXPECT_EQ(error("h: 1", HostPortRule::kPortRequired), "'h: 1': port must be a number 1..65535");
  EXPECT_EQ(transport::parse_discovery_server("x@h:1").error(),
            "'x@h:1': server id before '@' must be 0..255");
}

TEST(HostPort, ADiscoveryServerIdIsOptional) {
  const wire::Parsed<transport::DiscoveryServer> with_id = transport::parse_discovery_server("3@h:1");
  ASSERT_TRUE(with_id) << with_id.error();
  EXPECT_EQ(with_id->id, 3u);
  EXPECT_EQ(with_id->address.host, "h");
  const wire::Parsed<transport::DiscoveryServer> without = transport::parse_discovery_server("h:1");
  ASSERT_TRUE(without) << without.error();
  EXPECT_FALSE(without->id.has_value());
}

}  // namespace
}  // namespace rsg
