// The table agrees with docs/protocol.md's columns that it does not derive itself.
#include "rsg/wire/field_table.hpp"

#include <gtest/gtest.h>

namespace rsg {
namespace {

TEST(FieldTable, OffsetsInAFullFrameMatchTheSpec) {
  // Spot checks against the "offset in full frame" column; the rest follows by construction.
  EXPECT_EQ(kFullFrameOffsets[static_cast<std::size_t>(Field::O_T_EE)], 10);
  EXPECT_EQ(kFullFrameOffsets[static_cast<std::size_t>(Field::I_load)], 634);
  EXPECT_EQ(kFullFrameOffsets[static_cast<std::size_t>(Field::q)], 1082);
  EXPECT_EQ(kFullFrameOffsets[static_cast<std::size_t>(Field::current_errors)], 2106);
  EXPECT_EQ(kFullFrameOffsets[static_cast<std::size_t>(Field::robot_mode)], 2124);
}

TEST(FieldTable, CodeIsGroupBitAndMask) {
  // The seed's #define code: high byte = group bit, low byte = mask. E.g. elbow_c is 0x0280 (D2).
  const FieldInfo& elbow_c = info(Field::elbow_c);
  EXPECT_EQ((1U << elbow_c.group) << 8 | elbow_c.mask, 0x0280U);
  EXPECT_EQ(info(Field::time).group, 5);
  EXPECT_EQ(info(Field::time).mask, 0x08);
}

TEST(FieldTable, NamesAreUniqueAndFindable) {
  for (const FieldInfo& field : kFields) {
    const auto found = find_field(field.name);
    ASSERT_TRUE(found.has_value()) << field.name;
    EXPECT_EQ(*found, field.id());
  }
  EXPECT_FALSE(find_field("a").has_value());  // the seed's OCR spelling of q
}

TEST(FieldTable, ValueBytesWidenOnlyErrorSets) {
  EXPECT_EQ(info(Field::current_errors).value_bytes(), 8);
  EXPECT_EQ(info(Field::robot_mode).value_bytes(), 1);
  EXPECT_EQ(info(Field::O_T_EE).value_bytes(), 128);
}

}  // namespace
}  // namespace rsg
