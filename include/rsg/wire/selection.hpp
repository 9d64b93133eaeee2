// Which fields a frame carries: the header's group_select and data_select bytes.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "rsg/wire/field_table.hpp"
#include "rsg/wire/parsed.hpp"

namespace rsg::wire {

struct Selection {
  std::uint8_t group_select = 0;
  std::array<std::uint8_t, kGroupCount> data_select{};

  static constexpr Selection all() {
    Selection s;
    for (const FieldInfo& field : kFields) s.add(field.id());
    return s;
  }

  constexpr bool has_group(std::size_t group) const { return (group_select >> group) & 1U; }
  constexpr bool contains(Field field) const {
    const FieldInfo& row = info(field);
    return (data_select[row.group] & row.mask) != 0;
  }
  /// Selects the field and its group.
  constexpr void add(Field field) {
    const FieldInfo& row = info(field);
    group_select = static_cast<std::uint8_t>(group_select | (1U << row.group));
    data_select[row.group] = static_cast<std::uint8_t>(data_select[row.group] | row.mask);
  }
  /// Selects every field of the group.
  constexpr void add_group(std::size_t group) {
    for (const FieldInfo& field : kFields)
      if (field.group == group) add(field.id());
    group_select = static_cast<std::uint8_t>(group_select | (1U << group));
  }
  /// True when every group of `groups` is selected here (what a group view filters on).
  constexpr bool covers_groups(std::uint8_t groups) const { return (group_select & groups) == groups; }

  /// Bytes of the data section this selection implies.
  std::uint16_t data_bytes() const;

  /// Selects every field of `other` too: the union.
  constexpr Selection& operator|=(const Selection& other) {
    group_select = static_cast<std::uint8_t>(group_select | other.group_select);
    for (std::size_t group = 0; group < kGroupCount; ++group)
      data_select[group] = static_cast<std::uint8_t>(data_select[group] | other.data_select[group]);
    return *this;
  }
  /// The fields of both selections.
  friend constexpr Selection operator|(Selection a, const Selection& b) { return a |= b; }

  friend constexpr bool operator==(const Selection&, const Selection&) = default;
};

/// Parses a comma-separated list of field names ("q,dq,time") into a selection.
/// @return the selection, or a failure naming the offending item.
Parsed<Selection> parse_field_list(std::string_view list);
/// Parses a comma-separated list of group numbers ("0,2") into a selection of all their fields.
/// @return the selection, or a failure naming the offending item.
Parsed<Selection> parse_group_list(std::string_view list);
/// Parses a group list into a group_select bit mask.
/// @return the mask, or a failure naming the offending item.
Parsed<std::uint8_t> parse_group_mask(std::string_view list);

}  // namespace rsg::wire
