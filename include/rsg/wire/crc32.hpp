// CRC-32/ISO-HDLC (zlib's crc32) as the frame trailer uses it.
#pragma once

#include <cstdint>
#include <span>

namespace rsg::wire {

/// CRC-32 of `bytes` with the zlib convention (check value of "123456789" is 0xCBF43926).
/// Backed by ISA-L, which is about four times faster than zlib on a full frame.
std::uint32_t crc32(std::span<const std::uint8_t> bytes) noexcept;

}  // namespace rsg::wire
