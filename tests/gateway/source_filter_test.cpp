#include "gateway/source_filter.hpp"

#include <gtest/gtest.h>

#include "rsg/transport/udp_socket.hpp"

namespace rsg::gateway {
namespace {

bool allows(const SourceFilter& filter, const char* host_port) {
  return filter.allows(transport::Endpoint::parse(host_port).address());
}

SourceFilter filter_of(std::initializer_list<const char*> networks) {
  SourceFilter filter;
  for (const char* network : networks) {
    const wire::Parsed<Network> parsed = parse_network(network);
    EXPECT_TRUE(parsed) << network << ": " << parsed.error();
    if (parsed) filter.allow(*parsed);
  }
  return filter;
}

TEST(SourceFilter, EmptyFilterAllowsEveryone) {
  const SourceFilter filter;
  EXPECT_TRUE(allows(filter, "192.0.2.1:5000"));
  EXPECT_TRUE(allows(filter, "[2001:db8::1]:5000"));
}

TEST(SourceFilter, SingleIpv4Host) {
  const SourceFilter filter = filter_of({"192.0.2.7"});
  EXPECT_TRUE(allows(filter, "192.0.2.7:1"));
  EXPECT_FALSE(allows(filter, "192.0.2.8:1"));
  EXPECT_FALSE(allows(filter, "[2001:db8::1]:1"));
}

TEST(SourceFilter, Ipv4Prefix) {
  const SourceFilter filter = filter_of({"10.1.0.0/16"});
  EXPECT_TRUE(allows(filter, "10.1.200.3:1"));
  EXPECT_FALSE(allows(filter, "10.2.0.1:1"));
}

TEST(SourceFilter, PrefixNotOnAByteBoundary) {
  const SourceFilter filter = filter_of({"192.168.1.64/27"});  // .64 .. .95
  EXPECT_TRUE(allows(filter, "192.168.1.64:1"));
  EXPECT_TRUE(allows(filter, "192.168.1.95:1"));
  EXPECT_FALSE(allows(filter, "192.168.1.96:1"));
  EXPECT_FALSE(allows(filter, "192.168.1.63:1"));
}

TEST(SourceFilter, Ipv6PrefixAndHost) {
  const SourceFilter filter = filter_of({"2001:db8:1::/48", "[::1]"});
  EXPECT_TRUE(allows(filter, "[2001:db8:1:ffff::5]:1"));
  EXPECT_FALSE(allows(filter, "[2001:db8:2::5]:1"));
  EXPECT_TRUE(allows(filter, "[::1]:1"));
  EXPECT_FALSE(allows(filter, "127.0.0.1:1"));
}

TEST(SourceFilter, Ipv4NetworkMatchesIpv4MappedSenders) {
  // What a dual-stack IPv6 socket reports for an IPv4 peer.
  const SourceFilter filter = filter_of({"127.0.0.0/8"});
  EXPECT_TRUE(allows(filter, "[::ffff:127.0.0.1]:1"));
  EXPECT_FALSE(allows(filter, "[::ffff:10.0.0.1]:1"));
}

TEST(SourceFilter, ZeroPrefixAllowsTheWholeFamily) {
  const SourceFilter filter = filter_of({"0.0.0.0/0"});
  EXPECT_TRUE(allows(filter, "203.0.113.9:1"));
  EXPECT_FALSE(allows(filter, "[2001:db8::1]:1"));
}

TEST(SourceFilter, RejectsMalformedNetworksWithAReason) {
  for (const char* bad : {"", "host.example", "10.0.0.1/33", "10.0.0.1/", "10.0.0.1/x", "::1/129", "1.2.3"}) {
    const wire::Parsed<Network> parsed = parse_network(bad);
    EXPECT_FALSE(parsed) << bad;
    EXPECT_FALSE(parsed.error().empty()) << bad;
  }
}

}  // namespace
}  // namespace rsg::gateway
