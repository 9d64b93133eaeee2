#include "dds/internal/rtps_screen.hpp"

#include <cstring>

namespace rsg::dds::internal {
namespace {

constexpr std::uint32_t kHeaderBytes = 20;  // "RTPS", version, vendor, GUID prefix
constexpr std::uint32_t kSubmessageHeaderBytes = 4;
constexpr std::uint32_t kStatisticsBodyBytes = 56;  // locator, timestamp, sequence
constexpr std::uint8_t kPad = 0x01, kInfoTimestamp = 0x09;
constexpr std::uint8_t kVendorEprosima[2] = {0x01, 0x0F};

}  // namespace

RtpsScreen screen_rtps_datagram(const std::uint8_t* datagram, std::uint32_t size) noexcept {
  const RtpsScreen whole{size, RtpsScreen::Cut::kNone};
  if (size < kHeaderBytes || std::memcmp(datagram, "RTPS", 4) != 0) return whole;
  // Fast DDS reads statistics only from its own vendor's messages.
  if (datagram[6] != kVendorEprosima[0] || datagram[7] != kVendorEprosima[1]) return whole;
  std::uint32_t at = kHeaderBytes;
  while (size - at >= kSubmessageHeaderBytes) {
    const std::uint8_t id = datagram[at];
    const bool little_endian = (datagram[at + 1] & 0x01) != 0;
    const std::uint32_t length =
        little_endian ? datagram[at + 2] | datagram[at + 3] << 8 : datagram[at + 2] << 8 | datagram[at + 3];
    const std::uint32_t body = at + kSubmessageHeaderBytes;
    if (body + length > size) return whole;  // Fast DDS stops here too
    if (id == kStatisticsSubmessageId) {
      const bool trailing = length == kStatisticsBodyBytes && body + length == size;
      return {at, trailing ? RtpsScreen::Cut::kTrailing : RtpsScreen::Cut::kMisplaced};
    }
    // Length 0 means "to the end of the message", except for these two, which are empty.
    if (length == 0 && id != kInfoTimestamp && id != kPad) return whole;
    at = body + ((length + 3u) & ~3u);
    if (at >= size) return whole;
  }
  return whole;
}

}  // namespace rsg::dds::internal
