#include "capture/udp_packet.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <pcap/dlt.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "rsg/error.hpp"

namespace rsg::capture {
namespace {

constexpr std::uint8_t kUdp = 17;
constexpr std::size_t kIpv4Header = 20;
constexpr std::size_t kIpv6Header = 40;
constexpr std::size_t kUdpHeader = 8;
constexpr std::size_t kMaxIpPayload = 65535;
constexpr std::uint16_t kEtherIpv4 = 0x0800;
constexpr std::uint16_t kEtherIpv6 = 0x86DD;

std::uint16_t be16(std::span<const std::uint8_t> bytes, std::size_t at) {
  return static_cast<std::uint16_t>(bytes[at] << 8 | bytes[at + 1]);
}

void put16(std::uint8_t* out, std::uint16_t value) {
  out[0] = static_cast<std::uint8_t>(value >> 8);
  out[1] = static_cast<std::uint8_t>(value);
}

/// The UDP datagram inside an IP payload, or nothing when its header does not fit.
std::optional<UdpPacket> udp(std::chrono::nanoseconds time, const IpAddress& source,
                             const IpAddress& destination, std::span<const std::uint8_t> segment) {
  if (segment.size() < kUdpHeader) return std::nullopt;
  const std::size_t length = be16(segment, 4);
  // A zero length is what jumbograms use; a length beyond the bytes present is a cut capture.
  if (length < kUdpHeader || length > segment.size()) return std::nullopt;
  UdpPacket packet;
  packet.time = time;
  packet.from = {source, be16(segment, 0)};
  packet.to = {destination, be16(segment, 2)};
  packet.payload = segment.subspan(kUdpHeader, length - kUdpHeader);
  return packet;
}

IpAddress ipv4_address(std::span<const std::uint8_t> bytes) {
  IpAddress address;
  address.version = 4;
  std::copy_n(bytes.begin(), 4, address.bytes.begin());
  return address;
}

/// The ethertype and what follows it in a link-layer frame; ethertype 0 for anything else.
std::pair<std::uint16_t, std::span<const std::uint8_t>> network_layer(int linktype,
                                                                      std::span<const std::uint8_t> frame) {
  const auto by_version =
      [](std::span<const std::uint8_t> packet) -> std::pair<std::uint16_t, std::span<const std::uint8_t>> {
    if (packet.empty()) return {0, packet};
    const int version = packet[0] >> 4;
    return {version == 4 ? kEtherIpv4 : version == 6 ? kEtherIpv6 : 0, packet};
  };
  switch (linktype) {
    case DLT_EN10MB: {
      std::size_t at = 12;
      while (frame.size() >= at + 2) {
        const std::uint16_t type = be16(frame, at);
        if (type == 0x8100 || type == 0x88A8) {  // VLAN tags
          at += 4;
          continue;
        }
        return {type, frame.subspan(at + 2)};
      }
      return {0, {}};
    }
    case DLT_LINUX_SLL:
      if (frame.size() < 16) return {0, {}};
      return {be16(frame, 14), frame.subspan(16)};
    case DLT_LINUX_SLL2:
      if (frame.size() < 20) return {0, {}};
      return {be16(frame, 0), frame.subspan(20)};
    case DLT_NULL:
    case DLT_LOOP:  // a 4-byte address family, in host order (NULL) or network order (LOOP)
      if (frame.size() < 4) return {0, {}};
      return by_version(frame.subspan(4));
    case DLT_RAW:
    case DLT_IPV4:
    case DLT_IPV6:
#if DLT_RAW != 101
    case 101:  // LINKTYPE_RAW as stored in files where DLT_RAW differs
#endif
      return by_version(frame);
    default:
      return {0, {}};
  }
}

}  // namespace

std::string UdpEndpoint::to_string() const {
  char text[INET6_ADDRSTRLEN] = "";
  inet_ntop(ip.version == 6 ? AF_INET6 : AF_INET, ip.bytes.data(), text, sizeof text);
  return (ip.version == 6 ? "[" + std::string(text) + "]" : std::string(text)) + ":" + std::to_string(port);
}

UdpEndpoint endpoint_of(const sockaddr* address) {
  UdpEndpoint endpoint;
  if (address->sa_family == AF_INET) {
    const auto* v4 = reinterpret_cast<const sockaddr_in*>(address);
    std::memcpy(endpoint.ip.bytes.data(), &v4->sin_addr, 4);
    endpoint.port = ntohs(v4->sin_port);
  } else if (address->sa_family == AF_INET6) {
    const auto* v6 = reinterpret_cast<const sockaddr_in6*>(address);
    endpoint.ip.version = 6;
    std::memcpy(endpoint.ip.bytes.data(), &v6->sin6_addr, 16);
    endpoint.port = ntohs(v6->sin6_port);
  }
  return endpoint;
}

namespace {
UdpEndpoint as_ipv6(UdpEndpoint endpoint) {
  if (endpoint.ip.version == 6) return endpoint;
  std::array<std::uint8_t, 16> mapped{0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0xFF};
  std::copy_n(endpoint.ip.bytes.begin(), 4, mapped.begin() + 12);
  endpoint.ip = {6, mapped};
  return endpoint;
}
}  // namespace

std::size_t encode_raw_ip(const UdpEndpoint& source, const UdpEndpoint& destination,
                          std::span<const std::uint8_t> payload, std::span<std::uint8_t> out) noexcept {
  if (payload.size() > kMaxUdpPayload) return 0;
  const bool v6 = source.ip.version == 6 || destination.ip.version == 6;
  const UdpEndpoint from = v6 ? as_ipv6(source) : source;
  const UdpEndpoint to = v6 ? as_ipv6(destination) : destination;
  const std::size_t header = (v6 ? kIpv6Header : kIpv4Header) + kUdpHeader;
  if (out.size() < header + payload.size()) return 0;
  std::uint8_t* ip = out.data();
  std::fill_n(ip, header, std::uint8_t{0});
  const auto udp_length = static_cast<std::uint16_t>(kUdpHeader + payload.size());
  if (v6) {
    ip[0] = 0x60;
    put16(ip + 4, udp_length);
    ip[6] = kUdp;
    ip[7] = 64;
    std::copy_n(from.ip.bytes.begin(), 16, ip + 8);
    std::copy_n(to.ip.bytes.begin(), 16, ip + 24);
  } else {
    ip[0] = 0x45;
    put16(ip + 2, static_cast<std::uint16_t>(kIpv4Header + udp_length));
    ip[6] = 0x40;  // don't fragment: it is one packet as far as the capture is concerned
    ip[8] = 64;
    ip[9] = kUdp;
    std::copy_n(from.ip.bytes.begin(), 4, ip + 12);
    std::copy_n(to.ip.bytes.begin(), 4, ip + 16);
    std::uint32_t sum = 0;
    for (std::size_t i = 0; i < kIpv4Header; i += 2)
      sum += static_cast<std::uint32_t>(ip[i] << 8 | ip[i + 1]);
    while (sum > 0xFFFF) sum = (sum & 0xFFFF) + (sum >> 16);
    put16(ip + 10, static_cast<std::uint16_t>(~sum));
  }
  std::uint8_t* datagram = ip + header - kUdpHeader;
  put16(datagram, from.port);
  put16(datagram + 2, to.port);
  put16(datagram + 4, udp_length);
  // Checksum 0: "not computed", allowed over IPv4; over IPv6 readers flag it but still decode.
  std::copy(payload.begin(), payload.end(), datagram + kUdpHeader);
  return header + payload.size();
}

bool UdpExtractor::supports(int linktype) {
  switch (linktype) {
    case DLT_EN10MB:
    case DLT_LINUX_SLL:
    case DLT_LINUX_SLL2:
    case DLT_NULL:
    case DLT_LOOP:
    case DLT_RAW:
    case DLT_IPV4:
    case DLT_IPV6:
#if DLT_RAW != 101
    case 101:
#endif
      return true;
    default:
      return false;
  }
}

UdpExtractor::UdpExtractor(int linktype) : linktype_(linktype) {
  if (!supports(linktype)) throw InputError("link type " + std::to_string(linktype) + " is not supported");
}

std::optional<UdpPacket> UdpExtractor::extract(std::chrono::nanoseconds time,
                                               std::span<const std::uint8_t> frame) {
  const auto [type, packet] = network_layer(linktype_, frame);
  if (type == kEtherIpv4) return ipv4(time, packet);
  if (type == kEtherIpv6) return ipv6(time, packet);
  return std::nullopt;
}

std::optional<UdpPacket> UdpExtractor::ipv4(std::chrono::nanoseconds time,
                                            std::span<const std::uint8_t> packet) {
  if (packet.size() < kIpv4Header || packet[0] >> 4 != 4) return std::nullopt;
  const std::size_t header = (packet[0] & 0x0F) * 4u;
  const std::size_t total = be16(packet, 2);
  // Ethernet pads short frames: the IP total length, not the frame, says where the packet ends.
  if (header < kIpv4Header || total < header || total > packet.size() || packet[9] != kUdp)
    return std::nullopt;
  const std::span<const std::uint8_t> payload = packet.subspan(header, total - header);
  const std::uint16_t fragment = be16(packet, 6);
  if ((fragment & 0x3FFF) != 0) return reassemble(time, packet.first(header), payload);  // MF or an offset
  return udp(time, ipv4_address(packet.subspan(12)), ipv4_address(packet.subspan(16)), payload);
}

std::optional<UdpPacket> UdpExtractor::ipv6(std::chrono::nanoseconds time,
                                            std::span<const std::uint8_t> packet) {
  if (packet.size() < kIpv6Header || packet[0] >> 4 != 6 || packet[6] != kUdp) return std::nullopt;
  const std::size_t length = be16(packet, 4);
  if (kIpv6Header + length > packet.size()) return std::nullopt;
  IpAddress source, destination;
  source.version = destination.version = 6;
  std::copy_n(packet.begin() + 8, 16, source.bytes.begin());
  std::copy_n(packet.begin() + 24, 16, destination.bytes.begin());
  return udp(time, source, destination, packet.subspan(kIpv6Header, length));
}

std::optional<UdpPacket> UdpExtractor::reassemble(std::chrono::nanoseconds time,
                                                  std::span<const std::uint8_t> header,
                                                  std::span<const std::uint8_t> fragment) {
  const std::uint16_t flags_offset = be16(header, 6);
  const bool more = (flags_offset & 0x2000) != 0;
  const std::size_t offset = (flags_offset & 0x1FFFu) * 8u;
  if (offset + fragment.size() > kMaxIpPayload) return std::nullopt;
  if (more && fragment.size() % 8 != 0) return std::nullopt;  // only the last fragment may end unaligned

  std::array<std::uint8_t, 4> source{}, destination{};
  std::copy_n(header.begin() + 12, 4, source.begin());
  std::copy_n(header.begin() + 16, 4, destination.begin());
  const std::uint16_t id = be16(header, 4);

  Fragments* slot = nullptr;
  for (Fragments& candidate : slots_)
    if (candidate.in_use && candidate.id == id && candidate.source == source &&
        candidate.destination == destination)
      slot = &candidate;
  if (slot == nullptr) {
    slot = &*std::min_element(slots_.begin(), slots_.end(), [](const Fragments& a, const Fragments& b) {
      return a.in_use == b.in_use ? a.age < b.age : !a.in_use;
    });
    if (slot->data.empty()) {
      slot->data.resize(kMaxIpPayload);
      slot->covered.resize(kMaxIpPayload / 8 + 1);
    }
    std::fill(slot->covered.begin(), slot->covered.end(), std::uint8_t{0});
    slot->in_use = true;
    slot->source = source;
    slot->destination = destination;
    slot->id = id;
    slot->total = 0;
  }
  slot->age = ++fragments_seen_;
  std::copy(fragment.begin(), fragment.end(), slot->data.begin() + static_cast<std::ptrdiff_t>(offset));
  for (std::size_t unit = offset / 8; unit < (offset + fragment.size() + 7) / 8; ++unit)
    slot->covered[unit] = 1;
  if (!more) slot->total = offset + fragment.size();
  if (slot->total == 0) return std::nullopt;
  for (std::size_t unit = 0; unit < (slot->total + 7) / 8; ++unit)
    if (slot->covered[unit] == 0) return std::nullopt;

  slot->in_use = false;
  const std::span<const std::uint8_t> whole(slot->data.data(), slot->total);
  return udp(time, ipv4_address(source), ipv4_address(destination), whole);
}

}  // namespace rsg::capture
