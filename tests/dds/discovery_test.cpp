#include "rsg/dds/discovery.hpp"

#include <gtest/gtest.h>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <sstream>

#include "dds/internal/fastdds_compat.hpp"
#include "rsg/dds/profiles.hpp"

namespace rsg {
namespace {

namespace fdds = eprosima::fastdds::dds;
using rsg::dds::internal::DiscoveryProtocol;
using rsg::dds::rtps::IPLocator;

dds::DiscoveryOptions servers(std::vector<std::string> values) {
  dds::DiscoveryOptions options;
  options.servers = std::move(values);
  return options;
}

dds::DiscoveryOptions peers(std::vector<std::string> values) {
  dds::DiscoveryOptions options;
  options.peers = std::move(values);
  return options;
}

// `fastdds discovery -i 0` (Fast DDS 2) prints "Server GUID prefix: 44.53.00.5f.45.50.52.4f.53.49.4d.41";
// the third byte is the id. Fast DDS 3 finds servers by their locators alone.
TEST(Discovery, ServersBecomeClientOfTheIdsFastddsDiscoveryUses) {
  fdds::DomainParticipantQos qos;
  dds::apply_discovery(servers({"198.18.0.2:11811", "198.18.0.3:11812", "7@198.18.0.4:11813"}), 0, qos);
  const auto& config = qos.wire_protocol().builtin.discovery_config;
  EXPECT_EQ(config.discoveryProtocol, DiscoveryProtocol::CLIENT);
  ASSERT_EQ(config.m_DiscoveryServers.size(), 3u);
  const auto locator = rsg::dds::internal::discovery_server_locator(qos, 0);
  EXPECT_EQ(IPLocator::ip_to_string(locator), "198.18.0.2");
  EXPECT_EQ(locator.port, 11811u);
  EXPECT_EQ(IPLocator::ip_to_string(rsg::dds::internal::discovery_server_locator(qos, 2)), "198.18.0.4");
  if (RSG_FASTDDS_MAJOR >= 3) return;
  EXPECT_EQ(rsg::dds::internal::discovery_server_prefix(qos, 0), "44.53.00.5f.45.50.52.4f.53.49.4d.41");
  EXPECT_EQ(rsg::dds::internal::discovery_server_prefix(qos, 1), "44.53.01.5f.45.50.52.4f.53.49.4d.41");
  EXPECT_EQ(rsg::dds::internal::discovery_server_prefix(qos, 2), "44.53.07.5f.45.50.52.4f.53.49.4d.41");
}

TEST(Discovery, TheXmlExampleIsTheSameClient) {
  dds::load_profiles(dds::default_profiles_dir());
  fdds::DomainParticipantQos from_xml;
  ASSERT_EQ(fdds::DomainParticipantFactory::get_instance()->get_participant_qos_from_profile(
                "rsg_discovery_client", from_xml),
            rsg::dds::kOk);
  fdds::DomainParticipantQos from_flag;
  dds::apply_discovery(servers({"127.0.0.1:11811"}), 0, from_flag);
  EXPECT_EQ(from_xml.wire_protocol().builtin.discovery_config.discoveryProtocol,
            dds::internal::DiscoveryProtocol::CLIENT);
  EXPECT_EQ(from_xml.wire_protocol().builtin.discovery_config.m_DiscoveryServers,
            from_flag.wire_protocol().builtin.discovery_config.m_DiscoveryServers);
  // Both run the discovery cycle every 50 ms, not Fast DDS's 450 (docs/scaling.md).
  const rsg::dds::Duration fifty_ms(0, 50'000'000);
  EXPECT_EQ(from_flag.wire_protocol().builtin.discovery_config.discoveryServer_client_syncperiod, fifty_ms);
  EXPECT_EQ(from_xml.wire_protocol().builtin.discovery_config.discoveryServer_client_syncperiod, fifty_ms);
}

TEST(Discovery, APeerWithoutPortCoversEveryGatewayParticipantId) {
  fdds::DomainParticipantQos qos;
  dds::apply_discovery(peers({"198.18.0.2", "198.18.0.3:7412"}), 3, qos);
  const auto& peers = qos.wire_protocol().builtin.initialPeersList;
  ASSERT_EQ(peers.size(), 61u);
  // Metatraffic unicast port of participant id i on domain 3: 7400 + 250 * 3 + 10 + 2 * i.
  EXPECT_EQ(peers.begin()->port, 8160u);
  EXPECT_EQ((peers.begin() + 59)->port, 8160u + 2 * 59);
  EXPECT_EQ(IPLocator::ip_to_string(*(peers.begin() + 60)), "198.18.0.3");
  EXPECT_EQ((peers.begin() + 60)->port, 7412u);
  EXPECT_EQ(qos.wire_protocol().builtin.discovery_config.discoveryProtocol, DiscoveryProtocol::SIMPLE);
}

// rsg_participant announces every 0.5 s (a late joiner's lost reply, xml_profiles/rsg.xml); with a
// server or unicast peers every announcement goes to each of them, so those keep Fast DDS's 3 s.
TEST(Discovery, MulticastAnnouncesEveryHalfSecondServersAndPeersAtFastDdsDefault) {
  dds::load_profiles(dds::default_profiles_dir());
  const dds::Duration half_second(0, 500'000'000);
  const auto fastdds_default = dds::rtps::DiscoverySettings().leaseDuration_announcementperiod;
  ASSERT_NE(fastdds_default, half_second);
  for (const char* profile : {"rsg_participant", "rsg_participant_multicast"}) {
    fdds::DomainParticipantQos qos;
    ASSERT_EQ(fdds::DomainParticipantFactory::get_instance()->get_participant_qos_from_profile(profile, qos),
              rsg::dds::kOk);
    EXPECT_EQ(qos.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod, half_second)
        << profile;
    fdds::DomainParticipantQos multicast = qos;
    dds::apply_discovery(dds::DiscoveryOptions{}, 0, multicast);
    EXPECT_EQ(multicast.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod,
              half_second);
    fdds::DomainParticipantQos client = qos;
    apply_discovery(servers({"127.0.0.1:11811"}), 0, client);
    EXPECT_EQ(client.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod,
              fastdds_default);
    fdds::DomainParticipantQos peer = qos;
    apply_discovery(peers({"127.0.0.1"}), 0, peer);
    EXPECT_EQ(peer.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod,
              fastdds_default);
  }
}

TEST(Discovery, BadValuesNameThemselves) {
  EXPECT_NE(transport::parse_discovery_server("198.18.0.2").error().find("HOST:PORT"), std::string::npos);
  EXPECT_NE(transport::parse_discovery_server("256@h:1").error().find("0..255"), std::string::npos);
  EXPECT_NE(transport::parse_peer("h:70000").error().find("1..65535"), std::string::npos);
  EXPECT_TRUE(transport::parse_peer("h"));
  fdds::DomainParticipantQos qos;
  try {
    // Syntax is checked before any name is resolved (no DNS query from a unit test).
    dds::apply_discovery(servers({"gw.plant"}), 0, qos);
    FAIL() << "a server without a port was accepted";
  } catch (const rsg::InputError& error) {
    EXPECT_NE(std::string(error.what()).find("gw.plant"), std::string::npos);
  }
}

}  // namespace
}  // namespace rsg
