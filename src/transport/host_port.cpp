#include "rsg/transport/host_port.hpp"

#include <optional>
#include <utility>

#include "wire/internal/number.hpp"

namespace rsg::transport {

wire::Parsed<HostPort> parse_host_port(std::string_view value, HostPortRule rule) {
  const std::string quoted = "'" + std::string(value) + "'";
  const std::size_t colon = value.rfind(':');
  if (colon == std::string_view::npos) {
    if (rule != HostPortRule::kPortOptional || value.empty())
      return wire::ParseFailure{quoted + " is not HOST:PORT"};
    return HostPort{std::string(value), 0};
  }
  if (colon == 0 && rule != HostPortRule::kBindAddress)
    return wire::ParseFailure{quoted + " is not HOST:PORT"};
  const bool zero_allowed = rule == HostPortRule::kPortMayBeZero || rule == HostPortRule::kBindAddress;
  const std::optional<unsigned> port = wire::internal::parse_number<unsigned>(value.substr(colon + 1));
  if (!port || *port > 65535 || (*port == 0 && !zero_allowed))
    return wire::ParseFailure{quoted + ": port must be a number " + (zero_allowed ? "0" : "1") + "..65535"};
  return HostPort{std::string(value.substr(0, colon)), *port};
}

wire::Parsed<DiscoveryServer> parse_discovery_server(std::string_view value) {
  DiscoveryServer server;
  std::string_view host_port = value;
  if (const std::size_t at = value.find('@'); at != std::string_view::npos) {
    const std::optional<unsigned> given = wire::internal::parse_number<unsigned>(value.substr(0, at));
    if (!given || *given > 255)
      return wire::ParseFailure{"'" + std::string(value) + "': server id before '@' must be 0..255"};
    server.id = *given;
    host_port = value.substr(at + 1);
  }
  wire::Parsed<HostPort> address = parse_host_port(host_port, HostPortRule::kPortRequired);
  if (!address) return wire::ParseFailure{address.error()};
  server.address = std::move(address).value();
  return server;
}

wire::Parsed<HostPort> parse_peer(std::string_view value) {
  return parse_host_port(value, HostPortRule::kPortOptional);
}

}  // namespace rsg::transport
