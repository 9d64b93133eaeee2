#include "rsg/wire/selection.hpp"

#include <string>
#include <utility>

#include "wire/internal/group_bytes.hpp"
#include "wire/internal/number.hpp"
#include "wire/internal/text.hpp"

namespace rsg::wire {
namespace {

// Calls on_item (which returns "" or what is wrong with the item) for each trimmed item of a
// comma-separated list; returns the first complaint, or "".
template <class OnItem>
std::string for_each_item(std::string_view list, OnItem&& on_item) {
  if (list.empty()) return "empty list";
  while (true) {
    const std::size_t comma = list.find(',');
    const std::string_view item = internal::trim(list.substr(0, comma));
    if (std::string why = on_item(item); !why.empty()) return why;
    if (comma == std::string_view::npos) return {};
    list.remove_prefix(comma + 1);
  }
}

}  // namespace

std::uint16_t Selection::data_bytes() const {
  std::uint16_t total = 0;
  for (std::size_t group = 0; group < kGroupCount; ++group)
    total += internal::kSelectedBytes[group][data_select[group]];
  return total;
}

Parsed<Selection> parse_field_list(std::string_view list) {
  Selection selection;
  std::string why = for_each_item(list, [&](std::string_view item) -> std::string {
    const auto field = find_field(item);
    if (!field) return "'" + std::string(item) + "' is not a field name of docs/protocol.md";
    selection.add(*field);
    return {};
  });
  if (!why.empty()) return ParseFailure{std::move(why)};
  return selection;
}

Parsed<Selection> parse_group_list(std::string_view list) {
  Selection selection;
  std::string why = for_each_item(list, [&](std::string_view item) -> std::string {
    const std::optional<unsigned> group = internal::parse_number<unsigned>(item);
    if (!group || *group >= kGroupCount) return "'" + std::string(item) + "' is not a group number 0..5";
    selection.add_group(*group);
    return {};
  });
  if (!why.empty()) return ParseFailure{std::move(why)};
  return selection;
}

Parsed<std::uint8_t> parse_group_mask(std::string_view list) {
  Parsed<Selection> selection = parse_group_list(list);
  if (!selection) return ParseFailure{selection.error()};
  return selection->group_select;
}

}  // namespace rsg::wire
