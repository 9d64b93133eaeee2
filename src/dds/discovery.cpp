#include "rsg/dds/discovery.hpp"

#include <arpa/inet.h>
#include <netdb.h>

#include <memory>
#include <stdexcept>

#include "dds/internal/fastdds_compat.hpp"
#include "rsg/error.hpp"

namespace rsg::dds {
namespace {

using dds::rtps::IPLocator;
using dds::rtps::Locator_t;

std::string resolve_ipv4(const std::string& host, const std::string& value) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  if (const int status = ::getaddrinfo(host.c_str(), nullptr, &hints, &found); status != 0)
    throw InputError("'" + value + "': cannot resolve '" + host + "' to IPv4: " + gai_strerror(status));
  const std::unique_ptr<addrinfo, decltype(&::freeaddrinfo)> owner(found, &::freeaddrinfo);
  char text[INET_ADDRSTRLEN] = {};
  ::inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(found->ai_addr)->sin_addr, text, sizeof text);
  return text;
}

Locator_t udp_locator(const std::string& address, std::uint32_t port) {
  Locator_t locator;
  IPLocator::createLocator(LOCATOR_KIND_UDPv4, address, port, locator);
  return locator;
}

}  // namespace

void apply_discovery(const DiscoveryOptions& options, int domain,
                     eprosima::fastdds::dds::DomainParticipantQos& qos) {
  auto& builtin = qos.wire_protocol().builtin;
  for (std::size_t index = 0; index < options.servers.size(); ++index) {
    const std::string& value = options.servers[index];
    const wire::Parsed<transport::DiscoveryServer> parsed = transport::parse_discovery_server(value);
    if (!parsed) throw InputError(parsed.error());
    const unsigned id = parsed->id.value_or(static_cast<unsigned>(index));
    const transport::HostPort& server = parsed->address;
    dds::internal::add_discovery_server(qos, id, udp_locator(resolve_ipv4(server.host, value), server.port));
  }
  if (!options.servers.empty()) {
    builtin.discovery_config.discoveryProtocol = rsg::dds::internal::DiscoveryProtocol::CLIENT;
    // Fast DDS's default period delays a gateway's first sample at a reader; 50 ms (with
    // xml_profiles/discovery_server/ on the server) shortens that, with the same traffic once
    // matched (docs/deploying.md).
    builtin.discovery_config.discoveryServer_client_syncperiod = rsg::dds::Duration(0, 50'000'000);
  }

  if (!options.empty()) {
    // rsg_participant announces every 0.5 s for late joiners of multicast discovery
    // (xml_profiles/rsg.xml). Here each announcement is a datagram per server, or per peer port
    // (60 for a bare HOST), and a client asks its server again every 50 ms until it answers: keep
    // Fast DDS's period.
    builtin.discovery_config.leaseDuration_announcementperiod =
        rsg::dds::rtps::DiscoverySettings().leaseDuration_announcementperiod;
  }

  const auto& ports = qos.wire_protocol().port;
  for (const std::string& value : options.peers) {
    const wire::Parsed<transport::HostPort> parsed = transport::parse_peer(value);
    if (!parsed) throw InputError(parsed.error());
    const transport::HostPort& peer = *parsed;
    const std::string address = resolve_ipv4(peer.host, value);
    if (peer.port != 0) {
      builtin.initialPeersList.push_back(udp_locator(address, peer.port));
      continue;
    }
    for (std::uint32_t id = 0; id < transport::kGatewayParticipantIds; ++id)
      builtin.initialPeersList.push_back(
          udp_locator(address, ports.portBase + ports.domainIDGain * static_cast<std::uint32_t>(domain) +
                                   ports.offsetd1 + ports.participantIDGain * id));
  }
}

}  // namespace rsg::dds
