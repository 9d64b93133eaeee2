// How a participant finds the others when multicast is not there: a Fast DDS Discovery Server,
// or a fixed list of unicast peers. Every rsg program takes both as options
// (`--discovery-server`, `--peer`; src/app/discovery_cli.hpp) and applies them to the QoS of
// its participant profile:
//
//   rsg::dds::DiscoveryOptions discovery;
//   discovery.servers = {"198.18.0.2:11811"};
//   rsg::dds::Participant participant(domain, "rsg_participant", discovery);
//
// A server given as HOST:PORT is the one `fastdds discovery -i N -l HOST -p PORT` runs, where N
// is its position in the list (0 for the first), as with ROS_DISCOVERY_SERVER; `N@HOST:PORT`
// names the id explicitly. The server's GUID prefix follows from N (Fast DDS's
// get_server_client_default_guidPrefix), so nothing else has to be copied between machines.
#pragma once

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <string>
#include <vector>

#include "rsg/error.hpp"
#include "rsg/transport/host_port.hpp"  // parse_discovery_server, parse_peer, kGatewayParticipantIds

namespace rsg::dds {

struct DiscoveryOptions {
  /// Discovery Servers, "[ID@]HOST:PORT": the participant becomes their CLIENT and sends no
  /// multicast. Several servers are redundant: each one knows every client of any of them.
  std::vector<std::string> servers;
  /// Unicast initial peers, "HOST" or "HOST:PORT", for SIMPLE discovery without multicast:
  /// participant announcements go to these locators instead of the multicast group. A HOST alone
  /// stands for the metatraffic ports of participant ids 0..59 on the domain (the gateway takes
  /// its id from its pid, modulo 60); only one side of a pair has to list the other.
  std::vector<std::string> peers;

  bool empty() const { return servers.empty() && peers.empty(); }
};

/// Makes `qos` use the given servers or peers on `domain` (nothing changes when `options` is
/// empty). With either, the participant announces itself at Fast DDS's default period (3 s), not
/// rsg_participant's 0.5 s: each announcement then goes to every server or peer port. Resolves
/// host names (IPv4: rsg's participants use the UDPv4 transport).
/// @throws rsg::InputError naming a malformed or unresolvable server or peer.
void apply_discovery(const DiscoveryOptions& options, int domain,
                     eprosima::fastdds::dds::DomainParticipantQos& qos);

}  // namespace rsg::dds
