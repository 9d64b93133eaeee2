// The RTPS screen on arbitrary datagrams (src/dds/internal/rtps_screen.hpp): every rsg participant
// runs it on every datagram it receives from the network, before Fast DDS's parser.
//  - never reads outside the datagram, never hands on more than it got, cuts only at a submessage
//    boundary (a statistics submessage, or the first that fails a check);
//  - what it hands on passes it again whole (every check holds on what Fast DDS reads);
//  - what it hands on holds no statistics submessage that Fast DDS's own walk would read: the
//    oracle below is that walk (MessageReceiver::notify_network_statistics and
//    readSubmessageHeader, Fast DDS 2.9.1 to 3.1.2), written from its behaviour.
#include <cstdint>
#include <cstring>
#include <vector>

#include "dds/internal/rtps_screen.hpp"
#include "tests/fuzz/fuzz_check.hpp"

namespace {

/// True when Fast DDS would read a statistics submessage in `datagram`.
bool fastdds_reads_statistics(const std::uint8_t* datagram, std::uint32_t size) {
  if (size < 20 || std::memcmp(datagram, "RTPS", 4) != 0) return false;
  if (datagram[6] != 0x01 || datagram[7] != 0x0F) return false;
  std::uint32_t pos = 20;
  while (pos < size) {
    if (size - pos < 4) return false;
    const std::uint8_t id = datagram[pos];
    const bool little = (datagram[pos + 1] & 1) != 0;
    std::uint32_t length =
        little ? datagram[pos + 2] | (datagram[pos + 3] << 8) : (datagram[pos + 2] << 8) | datagram[pos + 3];
    pos += 4;
    if (pos + length > size) return false;
    bool last = false;
    if (length == 0 && id != 0x09 && id != 0x01) {
      length = size - pos;
      last = true;
    }
    if (id == 0x80) return length == 56 && pos + length <= size;
    if (last) return false;
    pos += (length + 3u) & ~3u;
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 65536) return 0;
  // A copy of exactly `size` bytes, so that ASan sees any read past the datagram.
  const std::vector<std::uint8_t> datagram(data, data + size);
  const auto bytes = static_cast<std::uint32_t>(size);
  const auto screen = rsg::dds::internal::screen_rtps_datagram(datagram.data(), bytes);
  FUZZ_REQUIRE(screen.forward_bytes <= bytes);
  using Cut = rsg::dds::internal::RtpsScreen::Cut;
  if (screen.cut == Cut::kNone) {
    FUZZ_REQUIRE(screen.forward_bytes == bytes);
  } else if (screen.cut == Cut::kInvalid) {
    // Cut at a submessage boundary (or the whole datagram refused): never inside the header.
    FUZZ_REQUIRE(screen.forward_bytes == 0 || (screen.forward_bytes >= 20 && screen.forward_bytes < bytes));
  } else {
    FUZZ_REQUIRE(screen.forward_bytes >= 20 && screen.forward_bytes < bytes);
    FUZZ_REQUIRE(datagram[screen.forward_bytes] == rsg::dds::internal::kStatisticsSubmessageId);
  }
  if (screen.forward_bytes <= 20) return 0;  // dropped: Fast DDS sees nothing
  const std::vector<std::uint8_t> forwarded(datagram.begin(), datagram.begin() + screen.forward_bytes);
  FUZZ_REQUIRE(!fastdds_reads_statistics(forwarded.data(), screen.forward_bytes));
  // Screening is idempotent: what was handed on passes whole.
  const auto again = rsg::dds::internal::screen_rtps_datagram(forwarded.data(), screen.forward_bytes);
  FUZZ_REQUIRE(again.cut == Cut::kNone && again.forward_bytes == screen.forward_bytes);
  return 0;
}
