#include "tools/sim/schedule.hpp"

#include "wire/internal/number.hpp"
#include "wire/internal/text.hpp"

namespace rsg::tools::sim {
namespace {

wire::Parsed<wire::Selection> parse_item(std::string_view item) {
  if (item == "all") return wire::Selection::all();
  wire::Selection selection;
  if (const auto field = wire::find_field(item)) {
    selection.add(*field);
    return selection;
  }
  // No field name starts with "g" followed by a digit, so group tokens cannot shadow a field.
  if (item.size() >= 2 && item.front() == 'g') {
    if (const std::optional<unsigned> group = wire::internal::parse_number<unsigned>(item.substr(1));
        group && *group < wire::kGroupCount) {
      selection.add_group(*group);
      return selection;
    }
  }
  return wire::ParseFailure{"'" + std::string(item) +
                            "' is neither a field name of docs/protocol.md, a group g0..g5, nor all"};
}

}  // namespace

wire::Parsed<wire::Selection> parse_selection_items(std::string_view list) {
  const std::string whole(list);
  wire::Selection selection;
  while (true) {
    const std::size_t comma = list.find(',');
    const std::string_view item = wire::internal::trim(list.substr(0, comma));
    if (item.empty()) return wire::ParseFailure{"empty item in '" + whole + "'"};
    const wire::Parsed<wire::Selection> parsed = parse_item(item);
    if (!parsed) return parsed;
    selection |= *parsed;
    if (comma == std::string_view::npos) return selection;
    list.remove_prefix(comma + 1);
  }
}

wire::Parsed<Schedule::Entry> parse_schedule_entry(std::string_view spec) {
  const std::size_t colon = spec.find(':');
  if (colon == std::string_view::npos) return wire::ParseFailure{"'" + std::string(spec) + "' is not N:LIST"};
  const std::string_view period_text = wire::internal::trim(spec.substr(0, colon));
  const std::uint64_t period = wire::internal::parse_number<std::uint64_t>(period_text).value_or(0);
  if (period == 0)
    return wire::ParseFailure{"'" + std::string(period_text) + "' in '" + std::string(spec) +
                              "' is not a period N >= 1"};
  wire::Parsed<wire::Selection> selection = parse_selection_items(spec.substr(colon + 1));
  if (!selection) return wire::ParseFailure{selection.error()};
  return Schedule::Entry{period, *selection};
}

wire::Selection Schedule::at(std::uint64_t frame) const {
  wire::Selection selection;
  for (const Entry& entry : entries_)
    if (frame % entry.period == 0) selection |= entry.selection;
  return selection;
}

}  // namespace rsg::tools::sim
