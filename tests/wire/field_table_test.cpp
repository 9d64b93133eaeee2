// The table agrees with docs/protocol.md's columns that it does not derive itself.
#include "rsg/wire/field_table.hpp"

#include <gtest/gtest.h>

namespace rsg {
namespace {

TEST(FieldTable, OffsetsInAFullFrameMatchTheSpec) {
  // Spot checks against the "offset in full frame" column; the rest follows by construction.
  EXPECT_EQ(wire::kFullFrameOffsets[static_cast<std::size_t>(wire::Field::O_T_EE)], 10);
  EXPECT_EQ(wire::kFullFrameOffsets[static_cast<std::size_t>(wire::Field::I_load)], 634);
  EXPECT_EQ(wire::kFullFrameOffsets[static_cast<std::size_t>(wire::Field::q)], 1082);
  EXPECT_EQ(wire::kFullFrameOffsets[static_cast<std::size_t>(wire::Field::current_errors)], 2106);
  EXPECT_EQ(wire::kFullFrameOffsets[static_cast<std::size_t>(wire::Field::robot_mode)], 2124);
}

TEST(FieldTable, CodeIsGroupBitAndMask) {
  // The seed's #define code: high byte = group bit, low byte = mask. E.g. elbow_c is 0x0280 (D2).
  const wire::FieldInfo& elbow_c = wire::info(wire::Field::elbow_c);
  EXPECT_EQ((1U << elbow_c.group) << 8 | elbow_c.mask, 0x0280U);
  EXPECT_EQ(wire::info(wire::Field::time).group, 5);
  EXPECT_EQ(wire::info(wire::Field::time).mask, 0x08);
}

TEST(FieldTable, NamesAreUniqueAndFindable) {
  for (const wire::FieldInfo& field : wire::kFields) {
    const auto found = wire::find_field(field.name);
    ASSERT_TRUE(found.has_value()) << field.name;
    EXPECT_EQ(*found, field.id());
  }
  EXPECT_FALSE(wire::find_field("a").has_value());  // the seed's OCR spelling of q
}

TEST(FieldTable, ValueBytesWidenOnlyErrorSets) {
  EXPECT_EQ(wire::info(wire::Field::current_errors).value_bytes(), 8);
  EXPECT_EQ(wire::info(wire::Field::robot_mode).value_bytes(), 1);
  EXPECT_EQ(wire::info(wire::Field::O_T_EE).value_bytes(), 128);
}

}  // namespace
}  // namespace rsg
