// The one `trim` of every parser of user text (selection lists, sim schedules, rsg_frame's lines).
#pragma once

#include <string_view>

namespace rsg::wire::internal {

/// `text` without the ASCII white space (space, tab, CR, LF, VT, FF) at either end.
constexpr std::string_view trim(std::string_view text) noexcept {
  constexpr std::string_view kWhitespace = " \t\r\n\v\f";
  const std::size_t first = text.find_first_not_of(kWhitespace);
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(kWhitespace) - first + 1);
}

}  // namespace rsg::wire::internal
