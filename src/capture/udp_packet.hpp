// UDP datagrams as a capture file holds them: to and from link-layer frames (Ethernet, Linux
// "cooked", raw IP, BSD loopback), with IPv4 reassembly, because a full 2137-byte SEND_BUF frame
// crosses a 1500-byte MTU in fragments. Pure byte work, no files: the fuzzer drives it directly.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

struct sockaddr;

namespace rsg::capture {

struct IpAddress {
  std::uint8_t version = 4;              ///< 4 or 6
  std::array<std::uint8_t, 16> bytes{};  ///< IPv4 uses the first 4
};

struct UdpEndpoint {
  IpAddress ip;
  std::uint16_t port = 0;
  std::string to_string() const;
};

/// One datagram with the time it was seen (since the Unix epoch). `payload` refers to storage of
/// whoever produced it and stays valid until that producer's next call.
struct UdpPacket {
  std::chrono::nanoseconds time{};
  UdpEndpoint from;
  UdpEndpoint to;
  std::span<const std::uint8_t> payload;
};

/// The address and port of a socket address (AF_INET or AF_INET6; anything else gives 0.0.0.0:0).
UdpEndpoint endpoint_of(const sockaddr* address);

/// Largest UDP payload over IPv4 (65535 - 20 - 8).
inline constexpr std::size_t kMaxUdpPayload = 65507;
/// IPv6 + UDP header bytes, the most `encode_raw_ip` puts in front of a payload.
inline constexpr std::size_t kMaxIpUdpHeader = 48;

/// Writes an unfragmented IPv4 or IPv6 packet (as LINKTYPE_RAW stores it) carrying `payload` from
/// `from` to `to` (IPv6 when either is: an IPv4 address then becomes IPv4-mapped). Returns its size,
/// or 0 when `out` is too small or the payload too large.
std::size_t encode_raw_ip(const UdpEndpoint& from, const UdpEndpoint& to,
                          std::span<const std::uint8_t> payload, std::span<std::uint8_t> out) noexcept;

/// Finds the UDP datagram in each captured frame of one link type. Fragmented IPv4 datagrams are put
/// back together from up to `kReassemblySlots` interleaved datagrams at once (the oldest
/// unfinished one gives way). IPv6 fragments and extension headers are not followed.
class UdpExtractor {
 public:
  static constexpr std::size_t kReassemblySlots = 8;

  /// Throws std::invalid_argument for a link type it cannot read (see `supports`).
  explicit UdpExtractor(int linktype);
  /// Ethernet (with VLAN tags), Linux cooked v1/v2, raw IP, IPv4, IPv6, BSD null/loop.
  static bool supports(int linktype);

  /// The datagram that `frame` carries or completes; nothing for other traffic, broken headers and
  /// fragments of unfinished datagrams.
  std::optional<UdpPacket> extract(std::chrono::nanoseconds time, std::span<const std::uint8_t> frame);

 private:
  struct Fragments {
    bool in_use = false;
    std::uint64_t age = 0;
    std::array<std::uint8_t, 4> source{}, destination{};
    std::uint16_t id = 0;
    std::size_t total = 0;           ///< payload bytes of the whole datagram, 0 until the last fragment came
    std::vector<std::uint8_t> data;  // IP payload, kMaxIpPayload bytes
    std::vector<std::uint8_t> covered;  // one flag per 8-byte unit of `data`
  };

  std::optional<UdpPacket> ipv4(std::chrono::nanoseconds time, std::span<const std::uint8_t> packet);
  std::optional<UdpPacket> ipv6(std::chrono::nanoseconds time, std::span<const std::uint8_t> packet);
  std::optional<UdpPacket> reassemble(std::chrono::nanoseconds time, std::span<const std::uint8_t> header,
                                      std::span<const std::uint8_t> fragment);

  int linktype_;
  std::uint64_t fragments_seen_ = 0;
  std::array<Fragments, kReassemblySlots> slots_;
};

}  // namespace rsg::capture
