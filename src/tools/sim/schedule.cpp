#include "schedule.hpp"

#include "rsg/wire/number.hpp"

namespace rsg::tools::sim {
namespace {

std::string_view trimmed(std::string_view text) {
  while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
  while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
  return text;
}

bool parse_item(std::string_view item, wire::Selection& selection, std::string& error) {
  if (item == "all") {
    selection = unite(selection, wire::Selection::all());
    return true;
  }
  if (const auto field = wire::find_field(item)) {
    selection.add(*field);
    return true;
  }
  // No field name starts with "g" followed by a digit, so group tokens cannot shadow a field.
  if (item.size() >= 2 && item.front() == 'g') {
    if (const std::optional<unsigned> group = wire::parse_number<unsigned>(item.substr(1));
        group && *group < wire::kGroupCount) {
      selection.add_group(*group);
      return true;
    }
  }
  error = "'" + std::string(item) + "' is neither a field name of docs/protocol.md, a group g0..g5, nor all";
  return false;
}

}  // namespace

wire::Selection unite(const wire::Selection& a, const wire::Selection& b) {
  wire::Selection both;
  both.group_select = static_cast<std::uint8_t>(a.group_select | b.group_select);
  for (std::size_t group = 0; group < wire::kGroupCount; ++group)
    both.data_select[group] = static_cast<std::uint8_t>(a.data_select[group] | b.data_select[group]);
  return both;
}

bool parse_selection_items(std::string_view list, wire::Selection& out, std::string& error) {
  wire::Selection selection;
  while (true) {
    const std::size_t comma = list.find(',');
    const std::string_view item = trimmed(list.substr(0, comma));
    if (item.empty()) {
      error = "empty item in '" + std::string(list) + "'";
      return false;
    }
    if (!parse_item(item, selection, error)) return false;
    if (comma == std::string_view::npos) break;
    list.remove_prefix(comma + 1);
  }
  out = selection;
  return true;
}

bool Schedule::add(std::string_view spec, std::string& error) {
  const std::size_t colon = spec.find(':');
  if (colon == std::string_view::npos) {
    error = "'" + std::string(spec) + "' is not N:LIST";
    return false;
  }
  const std::string_view period_text = trimmed(spec.substr(0, colon));
  const std::uint64_t period = wire::parse_number<std::uint64_t>(period_text).value_or(0);
  if (period == 0) {
    error = "'" + std::string(period_text) + "' in '" + std::string(spec) + "' is not a period N >= 1";
    return false;
  }
  wire::Selection selection;
  if (!parse_selection_items(spec.substr(colon + 1), selection, error)) return false;
  add(period, selection);
  return true;
}

wire::Selection Schedule::at(std::uint64_t frame) const {
  wire::Selection selection;
  for (const Entry& entry : entries_)
    if (frame % entry.period == 0) selection = unite(selection, entry.selection);
  return selection;
}

}  // namespace rsg::tools::sim
