#include "gateway/source_filter.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <cstring>
#include <optional>

#include "wire/internal/number.hpp"

namespace rsg::gateway {
namespace {

constexpr unsigned kMappedPrefixBits = 96;  // ::ffff:0:0/96 holds the IPv4 addresses

std::array<std::uint8_t, 16> mapped_ipv4(const in_addr& ipv4) {
  std::array<std::uint8_t, 16> address{};
  address[10] = 0xff;
  address[11] = 0xff;
  std::memcpy(address.data() + 12, &ipv4, 4);
  return address;
}

bool prefix_matches(const std::array<std::uint8_t, 16>& a, const std::array<std::uint8_t, 16>& b,
                    unsigned prefix_bits) {
  const unsigned whole_bytes = prefix_bits / 8;
  if (std::memcmp(a.data(), b.data(), whole_bytes) != 0) return false;
  const unsigned rest = prefix_bits % 8;
  if (rest == 0) return true;
  const auto mask = static_cast<std::uint8_t>(0xff << (8 - rest));
  return (a[whole_bytes] & mask) == (b[whole_bytes] & mask);
}

}  // namespace

wire::Parsed<Network> parse_network(std::string_view text) {
  const std::size_t slash = text.find('/');
  std::string host(text.substr(0, slash));
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);

  Network parsed{};
  unsigned max_bits = 0;
  unsigned offset_bits = 0;
  in_addr ipv4{};
  in6_addr ipv6{};
  if (::inet_pton(AF_INET, host.c_str(), &ipv4) == 1) {
    parsed.address = mapped_ipv4(ipv4);
    max_bits = 32;
    offset_bits = kMappedPrefixBits;
  } else if (::inet_pton(AF_INET6, host.c_str(), &ipv6) == 1) {
    std::memcpy(parsed.address.data(), &ipv6, 16);
    max_bits = 128;
  } else {
    return wire::ParseFailure{"'" + std::string(text) +
                              "' is not an IPv4 or IPv6 address (ADDR or ADDR/PREFIX)"};
  }

  unsigned bits = max_bits;
  if (slash != std::string_view::npos) {
    const std::optional<unsigned> number = wire::internal::parse_number<unsigned>(text.substr(slash + 1));
    if (!number || *number > max_bits)
      return wire::ParseFailure{"'" + std::string(text) + "': prefix must be a number 0.." +
                                std::to_string(max_bits)};
    bits = *number;
  }
  parsed.prefix_bits = offset_bits + bits;
  return parsed;
}

bool SourceFilter::allows(const sockaddr* source) const noexcept {
  if (networks_.empty()) return true;
  std::array<std::uint8_t, 16> address{};
  if (source->sa_family == AF_INET) {
    address = mapped_ipv4(reinterpret_cast<const sockaddr_in*>(source)->sin_addr);
  } else if (source->sa_family == AF_INET6) {
    std::memcpy(address.data(), &reinterpret_cast<const sockaddr_in6*>(source)->sin6_addr, 16);
  } else {
    return false;
  }
  for (const Network& network : networks_)
    if (prefix_matches(address, network.address, network.prefix_bits)) return true;
  return false;
}

}  // namespace rsg::gateway
