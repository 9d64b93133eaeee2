// Which senders the gateway accepts frames from (`--allow-from ADDR[/PREFIX]`).
//
// Networks are kept as IPv6 prefixes, IPv4 ones as IPv4-mapped addresses (::ffff:a.b.c.d/96+n),
// so one comparison serves both families, including IPv4 peers seen by a dual-stack socket.
#pragma once

#include <sys/socket.h>

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "rsg/wire/parsed.hpp"

namespace rsg::gateway {

/// A network as an IPv6 prefix (an IPv4 one IPv4-mapped).
struct Network {
  std::array<std::uint8_t, 16> address;
  unsigned prefix_bits;
};

/// Parses an `--allow-from` value, "ADDR" (a single host) or "ADDR/PREFIX", IPv4 or IPv6.
/// @return the network, or what is wrong with `text`.
wire::Parsed<Network> parse_network(std::string_view text);

class SourceFilter {
 public:
  /// Accepts frames from `network` too.
  void allow(const Network& network) { networks_.push_back(network); }

  /// True when no network was added (everyone is allowed) or `source` lies in one of them.
  bool allows(const sockaddr* source) const noexcept;

 private:
  std::vector<Network> networks_;
};

}  // namespace rsg::gateway
