// Selections, field lists and the spec's selection-request frame.
#include "rsg/wire/selection.hpp"

#include <gtest/gtest.h>

#include "rsg/wire/frame.hpp"
#include "wire/internal/text.hpp"

namespace rsg {
namespace {

TEST(Selection, AllFieldsImplyTheFullDataSection) {
  EXPECT_EQ(wire::Selection::all().data_bytes(), 2123);
  EXPECT_EQ(wire::Selection::all().group_select, 0x3F);
  EXPECT_EQ(wire::Selection::all().data_select[5], 0x0F);
}

TEST(Selection, ParsesFieldAndGroupLists) {
  const wire::Parsed<wire::Selection> fields = wire::parse_field_list("q, dq,time");
  ASSERT_TRUE(fields) << fields.error();
  EXPECT_TRUE(fields->contains(wire::Field::q));
  EXPECT_TRUE(fields->contains(wire::Field::time));
  EXPECT_EQ(fields->group_select, 0b100100);
  EXPECT_EQ(fields->data_bytes(), 56 + 56 + 8);

  const wire::Parsed<wire::Selection> group = wire::parse_group_list("2");
  ASSERT_TRUE(group) << group.error();
  EXPECT_EQ(group->data_bytes(), 368);
  EXPECT_EQ(group.error(), "");
  const wire::Parsed<wire::Selection> no_group = wire::parse_group_list("6");
  EXPECT_FALSE(no_group);
  EXPECT_NE(no_group.error().find("'6' is not a group number"), std::string::npos);
  const wire::Parsed<wire::Selection> no_field = wire::parse_field_list("q,nope");
  EXPECT_FALSE(no_field);
  EXPECT_NE(no_field.error().find("'nope'"), std::string::npos);
  EXPECT_EQ(wire::parse_group_list("").error(), "empty list");
  const wire::Parsed<std::uint8_t> mask = wire::parse_group_mask("0, 2");
  ASSERT_TRUE(mask) << mask.error();
  EXPECT_EQ(*mask, 0b101);
}

TEST(Selection, TheUnionHoldsTheFieldsAndGroupsOfBoth) {
  const wire::Selection joints = *wire::parse_field_list("q,dq");
  const wire::Selection group5 = *wire::parse_group_list("5");
  const wire::Selection both = joints | group5;
  EXPECT_TRUE(both.contains(wire::Field::q) && both.contains(wire::Field::dq));
  EXPECT_EQ(both.group_select, joints.group_select | group5.group_select);
  EXPECT_EQ(both.data_bytes(), joints.data_bytes() + group5.data_bytes());
  EXPECT_EQ(both | joints, both);
  EXPECT_EQ(joints | wire::Selection{}, joints);
  wire::Selection grown = joints;
  grown |= wire::Selection::all();
  EXPECT_EQ(grown, wire::Selection::all());
}

TEST(Selection, ListItemsAreTrimmedOfAnyWhiteSpace) {
  const wire::Parsed<wire::Selection> fields = wire::parse_field_list(" q,\tdq\r\n");
  ASSERT_TRUE(fields) << fields.error();
  EXPECT_EQ(*fields, *wire::parse_field_list("q,dq"));
  EXPECT_EQ(wire::internal::trim(" \t x y \r\n\v\f"), "x y");
  EXPECT_EQ(wire::internal::trim(" \t "), "");
  EXPECT_EQ(wire::internal::trim(""), "");
}

TEST(SelectionRequest, RoundTripsAndIsRejectedByTheStateDecoder) {
  const wire::Selection wanted = *wire::parse_group_list("2");
  std::array<std::uint8_t, wire::kSelectionRequestBytes> frame{};
  const wire::EncodeResult encoded = encode_selection_request(3, wanted, frame);
  ASSERT_TRUE(encoded) << encoded.error.message();
  EXPECT_EQ(frame[0], 0x33);
  EXPECT_EQ(frame[1], 0);
  EXPECT_EQ(frame[2], 0);

  const wire::SelectionRequestResult request = wire::decode_selection_request(frame);
  ASSERT_TRUE(request) << request.error.message();
  EXPECT_EQ(request.selection, wanted);
  EXPECT_EQ(request.packet_number, 3);

  const wire::DecodeResult as_state = wire::decode(frame);
  ASSERT_FALSE(as_state);
  EXPECT_EQ(as_state.error().category(), wire::ErrorCategory::kLengthMismatch);
}

TEST(SelectionRequest, EmptySelectionIsAlsoAValidEmptyStateFrame) {
  std::array<std::uint8_t, wire::kSelectionRequestBytes> frame{};
  ASSERT_TRUE(wire::encode_selection_request(0, wire::Selection{}, frame));
  EXPECT_TRUE(wire::decode(frame));
}

TEST(SelectionRequest, RejectsCorruption) {
  wire::Selection wanted = wire::Selection::all();
  std::array<std::uint8_t, wire::kSelectionRequestBytes> frame{};
  ASSERT_TRUE(wire::encode_selection_request(0, wanted, frame));
  frame[5] ^= 1;
  EXPECT_EQ(wire::decode_selection_request(frame).error.category(), wire::ErrorCategory::kBadCrc);
}

TEST(Encode, RefusesWhatADecoderWouldReject) {
  wire::Selection selection;
  selection.add(wire::Field::robot_mode);
  std::array<std::uint8_t, 64> storage{};  // zeroed host values; robot_mode patched below
  wire::FieldLayout layout;                // every field at offset 0 of `storage`
  std::array<std::uint8_t, wire::kMaxFrameBytes> out{};
  storage[0] = 7;
  EXPECT_EQ(wire::encode(0, selection, storage.data(), layout, out).error.category(),
            wire::ErrorCategory::kBadValue);
  storage[0] = 6;
  EXPECT_TRUE(wire::encode(0, selection, storage.data(), layout, out));
  EXPECT_EQ(wire::encode(16, selection, storage.data(), layout, out).error.category(),
            wire::ErrorCategory::kBadRequest);

  wire::Selection errors;
  errors.add(wire::Field::current_errors);
  storage = {};
  storage[4] = 0x20;  // bit 37
  EXPECT_EQ(wire::encode(0, errors, storage.data(), layout, out).error.category(),
            wire::ErrorCategory::kReservedBits);
  storage[4] = 0;
  storage[5] = 1;  // bit 40: no wire form at all
  EXPECT_EQ(wire::encode(0, errors, storage.data(), layout, out).error.category(),
            wire::ErrorCategory::kReservedBits);

  wire::Selection mismatched;
  mismatched.data_select[1] = 1;
  EXPECT_EQ(wire::encode(0, mismatched, storage.data(), layout, out).error.category(),
            wire::ErrorCategory::kSelectionMismatch);
}

}  // namespace
}  // namespace rsg
