// The SEND_BUF field table: the one description of the 44 robot-state fields.
//
// Everything that depends on which fields exist -- decode, encode, canonical JSON, the mapping onto
// the IDL `RobotState`, the simulator and the tests -- iterates this table instead of naming fields.
// The X-macro exists only so that code which must spell a field as a C++ identifier (the IDL
// accessor in the DDS layer, the `Field` enum) is generated from the same list.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace rsg::wire {

/// How one element of a field is stored on the wire.
enum class ElementType : std::uint8_t {
  kFloat64,   ///< IEEE-754 binary64, little-endian.
  kErrorSet,  ///< 5-byte little-endian bit set of the 37 error flags (bits 37..39 reserved).
  kUInt8,     ///< Unsigned byte (`robot_mode`).
  kUInt64,    ///< Unsigned 64-bit little-endian integer (`time`).
};

// X(name, index, group, mask, element type, count, wire bytes) -- as in docs/protocol.md.
#define RSG_FIELDS(X)                                          \
  X(O_T_EE, 0, 0, 0x01, kFloat64, 16, 128)                     \
  X(O_T_EE_d, 1, 0, 0x02, kFloat64, 16, 128)                   \
  X(F_T_EE, 2, 0, 0x04, kFloat64, 16, 128)                     \
  X(EE_T_K, 3, 0, 0x08, kFloat64, 16, 128)                     \
  X(m_ee, 4, 0, 0x10, kFloat64, 1, 8)                          \
  X(I_ee, 5, 0, 0x20, kFloat64, 9, 72)                         \
  X(F_x_Cee, 6, 0, 0x40, kFloat64, 3, 24)                      \
  X(m_load, 7, 0, 0x80, kFloat64, 1, 8)                        \
  X(I_load, 8, 1, 0x01, kFloat64, 9, 72)                       \
  X(F_x_Cload, 9, 1, 0x02, kFloat64, 3, 24)                    \
  X(m_total, 10, 1, 0x04, kFloat64, 1, 8)                      \
  X(I_total, 11, 1, 0x08, kFloat64, 9, 72)                     \
  X(F_x_Ctotal, 12, 1, 0x10, kFloat64, 3, 24)                  \
  X(elbow, 13, 1, 0x20, kFloat64, 2, 16)                       \
  X(elbow_d, 14, 1, 0x40, kFloat64, 2, 16)                     \
  X(elbow_c, 15, 1, 0x80, kFloat64, 2, 16)                     \
  X(delbow_c, 16, 2, 0x01, kFloat64, 2, 16)                    \
  X(ddelbow_c, 17, 2, 0x02, kFloat64, 2, 16)                   \
  X(tau_J, 18, 2, 0x04, kFloat64, 7, 56)                       \
  X(tau_J_d, 19, 2, 0x08, kFloat64, 7, 56)                     \
  X(dtau_J, 20, 2, 0x10, kFloat64, 7, 56)                      \
  X(q, 21, 2, 0x20, kFloat64, 7, 56)                           \
  X(q_d, 22, 2, 0x40, kFloat64, 7, 56)                         \
  X(dq, 23, 2, 0x80, kFloat64, 7, 56)                          \
  X(dq_d, 24, 3, 0x01, kFloat64, 7, 56)                        \
  X(ddq_d, 25, 3, 0x02, kFloat64, 7, 56)                       \
  X(joint_contact, 26, 3, 0x04, kFloat64, 7, 56)               \
  X(cartesian_contact, 27, 3, 0x08, kFloat64, 6, 48)           \
  X(joint_collision, 28, 3, 0x10, kFloat64, 7, 56)             \
  X(cartesian_collision, 29, 3, 0x20, kFloat64, 6, 48)         \
  X(tau_ext_hat_filtered, 30, 3, 0x40, kFloat64, 7, 56)        \
  X(O_F_ext_hat_K, 31, 3, 0x80, kFloat64, 6, 48)               \
  X(K_F_ext_hat_K, 32, 4, 0x01, kFloat64, 6, 48)               \
  X(O_dP_EE_d, 33, 4, 0x02, kFloat64, 6, 48)                   \
  X(O_T_EE_c, 34, 4, 0x04, kFloat64, 16, 128)                  \
  X(O_dP_EE_c, 35, 4, 0x08, kFloat64, 6, 48)                   \
  X(O_ddP_EE_c, 36, 4, 0x10, kFloat64, 6, 48)                  \
  X(theta, 37, 4, 0x20, kFloat64, 7, 56)                       \
  X(dtheta, 38, 4, 0x40, kFloat64, 7, 56)                      \
  X(current_errors, 39, 4, 0x80, kErrorSet, 1, 5)              \
  X(last_motion_errors, 40, 5, 0x01, kErrorSet, 1, 5)          \
  X(control_command_success_rate, 41, 5, 0x02, kFloat64, 1, 8) \
  X(robot_mode, 42, 5, 0x04, kUInt8, 1, 1)                     \
  X(time, 43, 5, 0x08, kUInt64, 1, 8)

/// Field identifiers, in field-index order (the order fields appear in a frame).
enum class Field : std::uint8_t {
#define RSG_FIELD_ENUM(name, index, group, mask, type, count, bytes) name = index,
  RSG_FIELDS(RSG_FIELD_ENUM)
#undef RSG_FIELD_ENUM
};

inline constexpr std::size_t kFieldCount = 44;
inline constexpr std::size_t kGroupCount = 6;

/// Bytes one element occupies on the wire.
constexpr std::uint16_t wire_element_bytes(ElementType type) {
  switch (type) {
    case ElementType::kFloat64:
    case ElementType::kUInt64:
      return 8;
    case ElementType::kErrorSet:
      return 5;
    case ElementType::kUInt8:
      return 1;
  }
  return 0;
}

/// Bytes one element occupies in host memory (an error set widens to a uint64).
constexpr std::uint16_t value_element_bytes(ElementType type) {
  return type == ElementType::kErrorSet ? 8 : wire_element_bytes(type);
}

/// One row of the table.
struct FieldInfo {
  std::string_view name;
  std::uint8_t index;
  std::uint8_t group;  ///< group_select bit / data_select byte that carries the field
  std::uint8_t mask;   ///< bit of data_select[group]
  ElementType type;
  std::uint8_t count;        ///< elements (16 for a 4x4 pose, 1 for a scalar)
  std::uint16_t wire_bytes;  ///< bytes in a frame

  constexpr Field id() const { return static_cast<Field>(index); }
  /// Bytes the value takes in host memory, e.g. in the IDL sample.
  constexpr std::uint16_t value_bytes() const { return count * value_element_bytes(type); }
  constexpr bool is_scalar() const { return count == 1; }
};

inline constexpr std::array<FieldInfo, kFieldCount> kFields = {{
#define RSG_FIELD_ROW(name, index, group, mask, type, count, bytes) \
  {#name, index, group, mask, ElementType::type, count, bytes},
    RSG_FIELDS(RSG_FIELD_ROW)
#undef RSG_FIELD_ROW
}};

constexpr const FieldInfo& info(Field field) { return kFields[static_cast<std::size_t>(field)]; }

/// Offset of each field in a frame that carries every field (the spec's "offset in full frame").
inline constexpr std::array<std::uint16_t, kFieldCount> kFullFrameOffsets = [] {
  std::array<std::uint16_t, kFieldCount> offsets{};
  std::uint16_t offset = 10;
  for (const FieldInfo& field : kFields) {
    offsets[field.index] = offset;
    offset = static_cast<std::uint16_t>(offset + field.wire_bytes);
  }
  return offsets;
}();

/// Data-section bytes of each group when all of its fields are selected.
inline constexpr std::array<std::uint16_t, kGroupCount> kGroupBytes = [] {
  std::array<std::uint16_t, kGroupCount> bytes{};
  for (const FieldInfo& field : kFields) bytes[field.group] += field.wire_bytes;
  return bytes;
}();

inline constexpr std::uint16_t kMaxDataBytes = [] {
  std::uint16_t total = 0;
  for (const FieldInfo& field : kFields) total += field.wire_bytes;
  return total;
}();

/// Looks a field up by its spec name (case-sensitive).
constexpr std::optional<Field> find_field(std::string_view name) {
  for (const FieldInfo& field : kFields)
    if (field.name == name) return field.id();
  return std::nullopt;
}

namespace detail {
constexpr bool table_is_consistent() {
  for (std::size_t i = 0; i < kFields.size(); ++i) {
    const FieldInfo& field = kFields[i];
    if (field.index != i) return false;
    if (field.index != field.group * 8 + std::countr_zero(field.mask)) return false;
    if (field.wire_bytes != field.count * wire_element_bytes(field.type)) return false;
  }
  return true;
}
}  // namespace detail

static_assert(detail::table_is_consistent(), "index, group, mask and bytes must agree");
static_assert(kMaxDataBytes == 2123, "docs/protocol.md: a full frame carries 2123 data bytes");
static_assert(kGroupBytes == std::array<std::uint16_t, kGroupCount>{624, 248, 368, 424, 437, 22});
static_assert(kFullFrameOffsets[static_cast<std::size_t>(Field::time)] == 2125);

}  // namespace rsg::wire
