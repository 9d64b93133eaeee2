// Whole-string number parsing: the one parser for every number rsg reads from text (flags, YAML,
// selection lists, addresses).
#pragma once

#include <charconv>
#include <optional>
#include <string_view>
#include <system_error>

namespace rsg::wire::internal {

/// Parses all of `text` as one decimal number of type `Number` (an integer or a floating-point type).
/// @return the number; std::nullopt when `text` is empty, has anything before or after the number
/// (signs excepted where `Number` allows them, white space included), or is out of `Number`'s range.
template <class Number>
std::optional<Number> parse_number(std::string_view text) noexcept {
  Number value{};
  const char* const last = text.data() + text.size();
  const auto [end, status] = std::from_chars(text.data(), last, value);
  if (text.empty() || status != std::errc() || end != last) return std::nullopt;
  return value;
}

}  // namespace rsg::wire::internal
