#include "rsg/wire/deframer.hpp"

#include <cstring>

#include "rsg/wire/crc32.hpp"

namespace rsg::wire {

Deframer::Scan Deframer::scan_at(std::size_t start) const noexcept {
  const std::size_t available = size_ - start;
  if (available == 0) return {Scan::kNeedMore, 0};
  const std::uint8_t* p = buffer_.data() + start;
  // Only a byte with the fixed request type can start a frame; anything else is garbage.
  if ((p[0] & 0xF0) != (kRequestType << 4)) return {Scan::kSkip, 1};
  if (available < 3) return {Scan::kNeedMore, 0};
  const std::size_t length = static_cast<std::size_t>(p[1] | p[2] << 8);
  if (length > kMaxDataBytes) return {Scan::kSkip, 1};
  const std::size_t size = kMinFrameBytes + length;
  if (available < size) return {Scan::kNeedMore, 0};
  std::uint32_t trailer;
  std::memcpy(&trailer, p + kHeaderBytes + length, sizeof trailer);
  if (crc32({p, kHeaderBytes + length}) != trailer) return {Scan::kSkip, 1};
  return {Scan::kFrame, size};
}

}  // namespace rsg::wire
