// Where each field's value lives inside some struct: the bridge that lets one decoder fill both
// the codec's own `StateValues` and the generated DDS `RobotState` without per-field code.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "rsg/wire/field_table.hpp"

namespace rsg::wire {

/// Byte offset of each field's value (host representation, `FieldInfo::value_bytes()` long)
/// from the start of the struct that holds it.
struct FieldLayout {
  std::array<std::uint32_t, kFieldCount> offsets{};

  std::byte* locate(void* base, Field field) const {
    return static_cast<std::byte*>(base) + offsets[static_cast<std::size_t>(field)];
  }
  const std::byte* locate(const void* base, Field field) const {
    return static_cast<const std::byte*>(base) + offsets[static_cast<std::size_t>(field)];
  }
};

}  // namespace rsg::wire
