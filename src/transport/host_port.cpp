#include "rsg/transport/host_port.hpp"

#include <optional>

#include "rsg/wire/number.hpp"

namespace rsg::transport {

std::string split_host_port(std::string_view value, HostPortRule rule, HostPort& out) {
  const std::string quoted = "'" + std::string(value) + "'";
  const std::size_t colon = value.rfind(':');
  if (colon == std::string_view::npos) {
    if (rule != HostPortRule::kPortOptional || value.empty()) return quoted + " is not HOST:PORT";
    out = HostPort{std::string(value), 0};
    return {};
  }
  if (colon == 0 && rule != HostPortRule::kBindAddress) return quoted + " is not HOST:PORT";
  const bool zero_allowed = rule == HostPortRule::kPortMayBeZero || rule == HostPortRule::kBindAddress;
  const std::optional<unsigned> port = wire::parse_number<unsigned>(value.substr(colon + 1));
  if (!port || *port > 65535 || (*port == 0 && !zero_allowed))
    return quoted + ": port must be a number " + (zero_allowed ? "0" : "1") + "..65535";
  out = HostPort{std::string(value.substr(0, colon)), *port};
  return {};
}

std::string split_discovery_server(std::string_view value, unsigned& id, HostPort& out) {
  std::string_view host_port = value;
  if (const std::size_t at = value.find('@'); at != std::string_view::npos) {
    const std::optional<unsigned> given = wire::parse_number<unsigned>(value.substr(0, at));
    if (!given || *given > 255) return "'" + std::string(value) + "': server id before '@' must be 0..255";
    id = *given;
    host_port = value.substr(at + 1);
  }
  return split_host_port(host_port, HostPortRule::kPortRequired, out);
}

std::string check_discovery_server(const std::string& value) {
  unsigned id = 0;
  HostPort parsed;
  return split_discovery_server(value, id, parsed);
}

std::string check_peer(const std::string& value) {
  HostPort parsed;
  return split_host_port(value, HostPortRule::kPortOptional, parsed);
}

}  // namespace rsg::transport
