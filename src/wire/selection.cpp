#include "rsg/wire/selection.hpp"

#include <charconv>

#include "group_bytes.hpp"
#include "rsg/wire/number.hpp"

namespace rsg::wire {
namespace {

template <class OnItem>
bool for_each_item(std::string_view list, std::string& error, OnItem&& on_item) {
  if (list.empty()) {
    error = "empty list";
    return false;
  }
  while (true) {
    const std::size_t comma = list.find(',');
    std::string_view item = list.substr(0, comma);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    if (!on_item(item)) return false;
    if (comma == std::string_view::npos) return true;
    list.remove_prefix(comma + 1);
  }
}

bool parse_group(std::string_view item, std::size_t& group, std::string& error) {
  const std::optional<unsigned> value = parse_number<unsigned>(item);
  if (!value || *value >= kGroupCount) {
    error = "'" + std::string(item) + "' is not a group number 0..5";
    return false;
  }
  group = *value;
  return true;
}

}  // namespace

std::uint16_t Selection::data_bytes() const {
  std::uint16_t total = 0;
  for (std::size_t group = 0; group < kGroupCount; ++group)
    total += detail::kSelectedBytes[group][data_select[group]];
  return total;
}

bool parse_field_list(std::string_view list, Selection& out, std::string& error) {
  Selection selection;
  const bool ok = for_each_item(list, error, [&](std::string_view item) {
    const auto field = find_field(item);
    if (!field) {
      error = "'" + std::string(item) + "' is not a field name of docs/protocol.md";
      return false;
    }
    selection.add(*field);
    return true;
  });
  if (ok) out = selection;
  return ok;
}

bool parse_group_list(std::string_view list, Selection& out, std::string& error) {
  Selection selection;
  const bool ok = for_each_item(list, error, [&](std::string_view item) {
    std::size_t group = 0;
    if (!parse_group(item, group, error)) return false;
    selection.add_group(group);
    return true;
  });
  if (ok) out = selection;
  return ok;
}

bool parse_group_mask(std::string_view list, std::uint8_t& out, std::string& error) {
  Selection selection;
  if (!parse_group_list(list, selection, error)) return false;
  out = selection.group_select;
  return true;
}

}  // namespace rsg::wire
