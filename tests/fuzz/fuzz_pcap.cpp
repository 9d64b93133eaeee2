// The capture reader on arbitrary bytes, the way rsg_sim --replay meets a file from the field.
//
// Input byte 0 chooses the mode. Even: the rest is a whole pcap/pcapng file, read through libpcap
// from memory. Odd: byte 1 picks a link type and the rest is a sequence of [2-byte length][frame]
// records for the link-layer decoder and the IPv4 reassembly directly, which file mode rarely
// reaches. Either way, every datagram found must survive a round trip through the writer's encoder.
#include <pcap/dlt.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <span>
#include <stdexcept>

#include "capture/pcap_file.hpp"
#include "capture/udp_packet.hpp"
#include "rsg/error.hpp"
#include "tests/fuzz/fuzz_check.hpp"

namespace {

using rsg::capture::UdpPacket;

constexpr std::array<int, 8> kLinkTypes = {DLT_EN10MB, DLT_LINUX_SLL, DLT_LINUX_SLL2, DLT_NULL,
                                           DLT_LOOP,   DLT_RAW,       DLT_IPV4,       DLT_IPV6};
constexpr int kMaxPackets = 256;

bool same(const rsg::capture::UdpEndpoint& a, const rsg::capture::UdpEndpoint& b) {
  return a.ip.version == b.ip.version && a.ip.bytes == b.ip.bytes && a.port == b.port;
}

void check_round_trip(const UdpPacket& packet) {
  static std::array<std::uint8_t, rsg::capture::kMaxIpUdpHeader + rsg::capture::kMaxUdpPayload> buffer;
  const std::size_t size = rsg::capture::encode_raw_ip(packet.from, packet.to, packet.payload, buffer);
  FUZZ_REQUIRE(size == packet.payload.size() + (packet.from.ip.version == 6 ? 48 : 28));
  rsg::capture::UdpExtractor raw(DLT_RAW);
  const auto again = raw.extract(packet.time, {buffer.data(), size});
  FUZZ_REQUIRE(again.has_value());
  FUZZ_REQUIRE(same(again->from, packet.from) && same(again->to, packet.to));
  FUZZ_REQUIRE(
      std::equal(again->payload.begin(), again->payload.end(), packet.payload.begin(), packet.payload.end()));
}

void read_file(std::span<const std::uint8_t> file) {
  // fmemopen wants a mutable buffer; libpcap only reads it.
  std::FILE* stream = fmemopen(const_cast<std::uint8_t*>(file.data()), file.size(), "rb");
  if (stream == nullptr) return;
  try {
    rsg::capture::PcapReader reader(stream);
    for (int i = 0; i < kMaxPackets; ++i) {
      const auto packet = reader.next();
      if (!packet) break;
      check_round_trip(*packet);
    }
  } catch (const rsg::Error&) {
    // A file libpcap rejects, or an unsupported link type: a clear error, which is the point.
  }
}

void decode_frames(int linktype, std::span<const std::uint8_t> records) {
  rsg::capture::UdpExtractor extractor(linktype);
  for (int i = 0; i < kMaxPackets && records.size() >= 2; ++i) {
    const std::size_t length = std::min<std::size_t>(records[0] | records[1] << 8, records.size() - 2);
    if (const auto packet = extractor.extract(std::chrono::nanoseconds(i), records.subspan(2, length)))
      check_round_trip(*packet);
    records = records.subspan(2 + length);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const std::span<const std::uint8_t> bytes(data, size);
  if ((data[0] & 1) == 0)
    read_file(bytes.subspan(1));
  else
    decode_frames(kLinkTypes[data[1] % kLinkTypes.size()], bytes.subspan(2));
  return 0;
}
