// The syntax of the addresses rsg reads from flags and configuration files: HOST:PORT, the
// Discovery Server's [ID@]HOST:PORT and a peer's HOST[:PORT]. Syntax only: no name is resolved
// here, so checking a configuration never touches the network and needs no DDS. Whoever opens a
// socket or a locator resolves the host (Endpoint::parse, apply_discovery).
//
// Like every check of text a user typed, each function returns what is wrong, in words for that
// user, or "" when the value is fine: the form CLI11 validators and GatewayConfig's keys take.
#pragma once

#include <string>
#include <string_view>

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
/// @return what is wrong with `value`, or "" with `out` filled in.
std::string split_host_port(std::string_view value, HostPortRule rule, HostPort& out);

/// A Fast DDS Discovery Server, "[ID@]HOST:PORT" with ID 0..255.
/// @return what is wrong, or "" with `out` filled in and `id` set when `value` names one (left
/// alone otherwise).
std::string split_discovery_server(std::string_view value, unsigned& id, HostPort& out);

/// @return what is wrong with `value` as [ID@]HOST:PORT, or "".
std::string check_discovery_server(const std::string& value);

/// @return what is wrong with `value` as a discovery peer, HOST[:PORT], or "".
std::string check_peer(const std::string& value);

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
