// Private to the codec: data bytes per group for every possible data_select byte. They turn "where
// does this field or group start in this frame" from a walk over the field table into a lookup.
#pragma once

#include <array>
#include <cstdint>

#include "rsg/wire/field_table.hpp"
#include "rsg/wire/selection.hpp"

namespace rsg::wire::internal {

/// kSelectedBytes[g][m]: bytes that group g carries when data_select[g] is m.
inline constexpr auto kSelectedBytes = [] {
  std::array<std::array<std::uint16_t, 256>, kGroupCount> table{};
  for (const FieldInfo& field : kFields)
    for (std::size_t mask = 0; mask < 256; ++mask)
      if (mask & field.mask) table[field.group][mask] += field.wire_bytes;
  return table;
}();

/// Where `field` starts inside its group's data, in a frame carrying `selection`: the bytes of the
/// group's selected fields with a lower bit.
constexpr std::uint16_t offset_in_group(const FieldInfo& field, const Selection& selection) {
  return kSelectedBytes[field.group][selection.data_select[field.group] & (field.mask - 1U)];
}

}  // namespace rsg::wire::internal
