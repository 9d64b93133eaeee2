#include "rsg/wire/crc32.hpp"

#include <isa-l/crc.h>

namespace rsg::wire {

std::uint32_t crc32(std::span<const std::uint8_t> bytes) noexcept {
  // crc32_gzip_refl is the reflected IEEE polynomial with zlib's pre/post inversion.
  return crc32_gzip_refl(0, bytes.data(), bytes.size());
}

}  // namespace rsg::wire
