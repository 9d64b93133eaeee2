// Hex text <-> bytes, as the conformance vectors and `rsg_frame --hex-lines` use it.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rsg/wire/parsed.hpp"

namespace rsg::wire {

std::string to_hex(std::span<const std::uint8_t> bytes);
/// Accepts upper or lower case.
/// @return the bytes, or a failure naming the first non-hex character and its column, or the odd
/// digit count.
Parsed<std::vector<std::uint8_t>> from_hex(std::string_view text);

}  // namespace rsg::wire
