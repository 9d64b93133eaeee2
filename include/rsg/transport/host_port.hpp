// The syntax of the addresses rsg reads from flags and configuration files: HOST:PORT, the
// Discovery Server's [ID@]HOST:PORT and a peer's HOST[:PORT]. Syntax only: no name is resolved
// here, so checking a configuration never touches the network and needs no DDS. Whoever opens a
// socket or a locator resolves the host (Endpoint::parse, apply_discovery).
//
// Like every parser of text a user typed, each function returns a wire::Parsed: the value, or what
// is wrong in words for that user (`.error()`, "" when fine, is what CLI11 validators and
// GatewayConfig's key checks take).
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "rsg/wire/parsed.hpp"

namespace rsg::transport {

/// A HOST:PORT split in two; `host` keeps IPv6 brackets ("[::1]").
struct HostPort {
  std::string host;
  unsigned port = 0;  ///< 0 when none was given (HostPortRule::kPortOptional)
};

enum class HostPortRule {
  kPortRequired,   ///< HOST:PORT, PORT 1..65535
  kPortMayBeZero,  ///< HOST:PORT, PORT 0..65535 (0: the kernel picks one)
  kPortOptional,   ///< HOST or HOST:PORT
  kBindAddress,    ///< [HOST]:PORT, PORT 0..65535: a local address to bind (HOST "" or "*": any)
};

/// Splits `value` into host and port by `rule`.
/// @return the host and port, or what is wrong with `value`.
wire::Parsed<HostPort> parse_host_port(std::string_view value, HostPortRule rule);

/// A Fast DDS Discovery Server as a user names it, "[ID@]HOST:PORT".
struct DiscoveryServer {
  std::optional<unsigned> id;  ///< 0..255 when given; else the server's position in the list
  HostPort address;
};

/// Parses "[ID@]HOST:PORT" with ID 0..255.
/// @return the server, or what is wrong with `value`.
wire::Parsed<DiscoveryServer> parse_discovery_server(std::string_view value);

/// Parses a discovery peer, HOST[:PORT].
/// @return the peer (port 0 when none was given), or what is wrong with `value`.
wire::Parsed<HostPort> parse_peer(std::string_view value);

/// How many participant ids the gateway picks from (its pid modulo this), and so how many ports a
/// bare-HOST peer is tried on: 60 keeps every domain's ports below 65536.
inline constexpr unsigned kGatewayParticipantIds = 60;

/// The help of --discovery-server and --peer (and of their configuration keys), the same on every
/// rsg program.
inline constexpr std::string_view kDiscoveryServerHelp =
    "Find the other participants through this Fast DDS Discovery Server, [ID@]HOST:PORT (repeatable; "
    "ID defaults to the position in the list, as `fastdds discovery -i ID`)";
inline constexpr std::string_view kPeerHelp =
    "Send discovery announcements to this unicast peer instead of multicast, HOST[:PORT] "
    "(repeatable; HOST alone covers participant ids 0..59)";

}  // namespace rsg::transport
