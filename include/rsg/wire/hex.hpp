// Hex text <-> bytes, as the conformance vectors and `rsg_frame --hex-lines` use it.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rsg::wire {

std::string to_hex(std::span<const std::uint8_t> bytes);
/// Accepts upper or lower case; fails on odd length or a non-hex character.
bool from_hex(std::string_view text, std::vector<std::uint8_t>& out);

}  // namespace rsg::wire
