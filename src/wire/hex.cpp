#include "rsg/wire/hex.hpp"

#include <array>
#include <cstdio>

namespace rsg::wire {

std::string to_hex(std::span<const std::uint8_t> bytes) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string text(bytes.size() * 2, '0');
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    text[2 * i] = kDigits[bytes[i] >> 4];
    text[2 * i + 1] = kDigits[bytes[i] & 0x0F];
  }
  return text;
}

Parsed<std::vector<std::uint8_t>> from_hex(std::string_view text) {
  auto nibble = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  for (std::size_t i = 0; i < text.size(); ++i)
    if (nibble(text[i]) < 0) {
      std::array<char, 64> message{};
      std::snprintf(message.data(), message.size(), "byte 0x%02x at column %zu is not a hex digit",
                    static_cast<unsigned char>(text[i]), i + 1);
      return ParseFailure{message.data()};
    }
  if (text.size() % 2 != 0)
    return ParseFailure{"odd number of hex digits (" + std::to_string(text.size()) + ")"};
  std::vector<std::uint8_t> bytes(text.size() / 2);
  for (std::size_t i = 0; i < bytes.size(); ++i)
    bytes[i] = static_cast<std::uint8_t>(nibble(text[2 * i]) << 4 | nibble(text[2 * i + 1]));
  return bytes;
}

}  // namespace rsg::wire
