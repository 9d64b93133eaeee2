#include "rsg/dds/discovery.hpp"

#include <arpa/inet.h>
#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastrtps/utils/IPLocator.h>
#include <netdb.h>

#include <memory>
#include <stdexcept>

#include "rsg/wire/number.hpp"

namespace rsg {
namespace {

using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::Locator_t;

struct HostPort {
  std::string host;
  unsigned port = 0;  // 0: none given
};

// "HOST:PORT", or "HOST" when the port is optional. Returns what is wrong, or "".
std::string split_host_port(const std::string& value, bool port_required, HostPort& out) {
  const std::size_t colon = value.rfind(':');
  if (colon == std::string::npos) {
    if (port_required || value.empty()) return "'" + value + "' is not HOST:PORT";
    out.host = value;
    return {};
  }
  out.host = value.substr(0, colon);
  if (out.host.empty()) return "'" + value + "' has no HOST";
  out.port = parse_number<unsigned>(std::string_view(value).substr(colon + 1)).value_or(0);
  if (out.port == 0 || out.port > 65535) return "'" + value + "': port must be a number 1..65535";
  return {};
}

// "[ID@]HOST:PORT"; `id` is left alone when the value names none.
std::string split_server(const std::string& value, unsigned& id, HostPort& out) {
  std::string host_port = value;
  if (const std::size_t at = value.find('@'); at != std::string::npos) {
    const std::optional<unsigned> given = parse_number<unsigned>(std::string_view(value).substr(0, at));
    if (!given || *given > 255) return "'" + value + "': server id before '@' must be 0..255";
    id = *given;
    host_port = value.substr(at + 1);
  }
  return split_host_port(host_port, /*port_required=*/true, out);
}

std::string resolve_ipv4(const std::string& host, const std::string& value) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  if (const int status = ::getaddrinfo(host.c_str(), nullptr, &hints, &found); status != 0)
    throw std::invalid_argument("'" + value + "': cannot resolve '" + host +
                                "' to IPv4: " + gai_strerror(status));
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

std::string check_discovery_server(const std::string& value) {
  unsigned id = 0;
  HostPort parsed;
  return split_server(value, id, parsed);
}

std::string check_peer(const std::string& value) {
  HostPort parsed;
  return split_host_port(value, /*port_required=*/false, parsed);
}

void apply_discovery(const DiscoveryOptions& options, int domain,
                     eprosima::fastdds::dds::DomainParticipantQos& qos) {
  auto& builtin = qos.wire_protocol().builtin;
  for (std::size_t index = 0; index < options.servers.size(); ++index) {
    const std::string& value = options.servers[index];
    auto id = static_cast<unsigned>(index);
    HostPort server;
    if (auto error = split_server(value, id, server); !error.empty()) throw std::invalid_argument(error);
    eprosima::fastdds::rtps::RemoteServerAttributes remote;
    eprosima::fastdds::rtps::get_server_client_default_guidPrefix(static_cast<int>(id), remote.guidPrefix);
    remote.metatrafficUnicastLocatorList.push_back(
        udp_locator(resolve_ipv4(server.host, value), server.port));
    builtin.discovery_config.m_DiscoveryServers.push_back(remote);
  }
  if (!options.servers.empty()) {
    builtin.discovery_config.discoveryProtocol = eprosima::fastrtps::rtps::DiscoveryProtocol_t::CLIENT;
    // Fast DDS's 450 ms cycle made a gateway's first sample reach a reader ~1.1 s after start; at
    // 50 ms (with xml_profiles/discovery_server/ on the server) it is ~0.4 s, same traffic once matched.
    builtin.discovery_config.discoveryServer_client_syncperiod =
        eprosima::fastrtps::Duration_t(0, 50'000'000);
  }

  if (!options.empty()) {
    // rsg_participant announces every 0.5 s for late joiners of multicast discovery
    // (xml_profiles/rsg.xml). Here each announcement is a datagram per server, or per peer port
    // (60 for a bare HOST), and a client asks its server again every 50 ms until it answers: keep
    // Fast DDS's period.
    builtin.discovery_config.leaseDuration_announcementperiod =
        eprosima::fastrtps::rtps::DiscoverySettings().leaseDuration_announcementperiod;
  }

  const auto& ports = qos.wire_protocol().port;
  for (const std::string& value : options.peers) {
    HostPort peer;
    if (auto error = split_host_port(value, /*port_required=*/false, peer); !error.empty())
      throw std::invalid_argument(error);
    const std::string address = resolve_ipv4(peer.host, value);
    if (peer.port != 0) {
      builtin.initialPeersList.push_back(udp_locator(address, peer.port));
      continue;
    }
    for (std::uint32_t id = 0; id < kGatewayParticipantIds; ++id)
      builtin.initialPeersList.push_back(
          udp_locator(address, ports.portBase + ports.domainIDGain * static_cast<std::uint32_t>(domain) +
                                   ports.offsetd1 + ports.participantIDGain * id));
  }
}

}  // namespace rsg
