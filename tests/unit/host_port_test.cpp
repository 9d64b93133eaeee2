// The one HOST:PORT syntax that configuration, discovery and sockets share.
#include "rsg/transport/host_port.hpp"

#include <gtest/gtest.h>

#include "rsg/transport/udp_socket.hpp"

namespace rsg {
namespace {

TEST(HostPort, EachRuleAcceptsWhatItNames) {
  transport::HostPort out;
  EXPECT_EQ(transport::split_host_port("robot:17000", transport::HostPortRule::kPortRequired, out), "");
  EXPECT_EQ(out.host, "robot");
  EXPECT_EQ(out.port, 17000u);
  EXPECT_EQ(transport::split_host_port("[::1]:5", transport::HostPortRule::kPortRequired, out), "");
  EXPECT_EQ(out.host, "[::1]");
  EXPECT_EQ(transport::split_host_port("0.0.0.0:0", transport::HostPortRule::kPortMayBeZero, out), "");
  EXPECT_EQ(transport::split_host_port("peer", transport::HostPortRule::kPortOptional, out), "");
  EXPECT_EQ(out.host, "peer");
  EXPECT_EQ(out.port, 0u);
  EXPECT_EQ(transport::split_host_port(":0", transport::HostPortRule::kBindAddress, out), "");
  EXPECT_EQ(out.host, "");
}

TEST(HostPort, BadValuesSayWhatIsWrong) {
  transport::HostPort out;
  EXPECT_EQ(transport::split_host_port("robot", transport::HostPortRule::kPortRequired, out),
            "'robot' is not HOST:PORT");
  EXPECT_EQ(transport::split_host_port(":1", transport::HostPortRule::kPortRequired, out),
            "':1' is not HOST:PORT");
  EXPECT_EQ(transport::split_host_port("", transport::HostPortRule::kPortOptional, out),
            "'' is not HOST:PORT");
  EXPECT_EQ(transport::split_host_port("h:0", transport::HostPortRule::kPortRequired, out),
            "'h:0': port must be a number 1..65535");
  EXPECT_EQ(transport::split_host_port("h:65536", transport::HostPortRule::kPortMayBeZero, out),
            "'h:65536': port must be a number 0..65535");
  EXPECT_EQ(transport::split_host_port("h: 1", transport::HostPortRule::kPortRequired, out),
            "'h: 1': port must be a number 1..65535");
  unsigned id = 7;
  EXPECT_EQ(transport::split_discovery_server("x@h:1", id, out),
            "'x@h:1': server id before '@' must be 0..255");
  EXPECT_EQ(id, 7u);
  EXPECT_EQ(transport::split_discovery_server("3@h:1", id, out), "");
  EXPECT_EQ(id, 3u);
}

TEST(HostPort, EndpointParseUsesTheSameSyntax) {
  EXPECT_EQ(transport::Endpoint::parse(":0").to_string(), "0.0.0.0:0");
  EXPECT_EQ(transport::Endpoint::parse("*:17000").to_string(), "0.0.0.0:17000");
  EXPECT_EQ(transport::Endpoint::parse("[::1]:9").to_string(), "[::1]:9");
  EXPECT_THROW(transport::Endpoint::parse("127.0.0.1"), std::invalid_argument);
  EXPECT_THROW(transport::Endpoint::parse("127.0.0.1:x"), std::invalid_argument);
}

}  // namespace
}  // namespace rsg
