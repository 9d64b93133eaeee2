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

namespace rsg::gateway {

class SourceFilter {
 public:
  /// Adds "ADDR" (a single host) or "ADDR/PREFIX". On failure returns false and says why in `error`.
  bool allow(std::string_view network, std::string& error);

  /// True when no network was added (everyone is allowed) or `source` lies in one of them.
  bool allows(const sockaddr* source) const noexcept;

  bool allows_everyone() const { return networks_.empty(); }

 private:
  using Address = std::array<std::uint8_t, 16>;
  struct Network {
    Address address;
    unsigned prefix_bits;
  };

  std::vector<Network> networks_;
};

/// Checks the syntax of an `--allow-from` value without keeping it.
bool is_valid_network(std::string_view network, std::string& error);

}  // namespace rsg::gateway
