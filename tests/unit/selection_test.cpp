// Selections, field lists and the spec's selection-request frame.
#include "rsg/wire/selection.hpp"

#include <gtest/gtest.h>

#include "rsg/wire/frame.hpp"

namespace rsg {
namespace {

TEST(Selection, AllFieldsImplyTheFullDataSection) {
  EXPECT_EQ(Selection::all().data_bytes(), 2123);
  EXPECT_EQ(Selection::all().group_select, 0x3F);
  EXPECT_EQ(Selection::all().data_select[5], 0x0F);
}

TEST(Selection, ParsesFieldAndGroupLists) {
  Selection selection;
  std::string error;
  ASSERT_TRUE(parse_field_list("q, dq,time", selection, error)) << error;
  EXPECT_TRUE(selection.contains(Field::q));
  EXPECT_TRUE(selection.contains(Field::time));
  EXPECT_EQ(selection.group_select, 0b100100);
  EXPECT_EQ(selection.data_bytes(), 56 + 56 + 8);

  ASSERT_TRUE(parse_group_list("2", selection, error));
  EXPECT_EQ(selection.data_bytes(), 368);
  EXPECT_FALSE(parse_group_list("6", selection, error));
  EXPECT_NE(error.find("'6' is not a group number"), std::string::npos);
  EXPECT_FALSE(parse_field_list("q,nope", selection, error));
  EXPECT_NE(error.find("'nope'"), std::string::npos);
}

TEST(SelectionRequest, RoundTripsAndIsRejectedByTheStateDecoder) {
  Selection wanted;
  std::string error;
  ASSERT_TRUE(parse_group_list("2", wanted, error));
  std::array<std::uint8_t, kSelectionRequestBytes> frame{};
  const EncodeResult encoded = encode_selection_request(3, wanted, frame);
  ASSERT_TRUE(encoded) << encoded.error.message();
  EXPECT_EQ(frame[0], 0x33);
  EXPECT_EQ(frame[1], 0);
  EXPECT_EQ(frame[2], 0);

  const SelectionRequestResult request = decode_selection_request(frame);
  ASSERT_TRUE(request) << request.error.message();
  EXPECT_EQ(request.selection, wanted);
  EXPECT_EQ(request.packet_number, 3);

  const DecodeResult as_state = decode(frame);
  ASSERT_FALSE(as_state);
  EXPECT_EQ(as_state.error().category(), ErrorCategory::kLengthMismatch);
}

TEST(SelectionRequest, EmptySelectionIsAlsoAValidEmptyStateFrame) {
  std::array<std::uint8_t, kSelectionRequestBytes> frame{};
  ASSERT_TRUE(encode_selection_request(0, Selection{}, frame));
  EXPECT_TRUE(decode(frame));
}

TEST(SelectionRequest, RejectsCorruption) {
  Selection wanted = Selection::all();
  std::array<std::uint8_t, kSelectionRequestBytes> frame{};
  ASSERT_TRUE(encode_selection_request(0, wanted, frame));
  frame[5] ^= 1;
  EXPECT_EQ(decode_selection_request(frame).error.category(), ErrorCategory::kBadCrc);
}

TEST(Encode, RefusesWhatADecoderWouldReject) {
  Selection selection;
  selection.add(Field::robot_mode);
  std::array<std::uint8_t, 64> storage{};  // zeroed host values; robot_mode patched below
  FieldLayout layout;                      // every field at offset 0 of `storage`
  std::array<std::uint8_t, kMaxFrameBytes> out{};
  storage[0] = 7;
  EXPECT_EQ(encode(0, selection, storage.data(), layout, out).error.category(), ErrorCategory::kBadValue);
  storage[0] = 6;
  EXPECT_TRUE(encode(0, selection, storage.data(), layout, out));
  EXPECT_EQ(encode(16, selection, storage.data(), layout, out).error.category(), ErrorCategory::kBadRequest);

  Selection errors;
  errors.add(Field::current_errors);
  storage = {};
  storage[4] = 0x20;  // bit 37
  EXPECT_EQ(encode(0, errors, storage.data(), layout, out).error.category(), ErrorCategory::kReservedBits);
  storage[4] = 0;
  storage[5] = 1;  // bit 40: no wire form at all
  EXPECT_EQ(encode(0, errors, storage.data(), layout, out).error.category(), ErrorCategory::kReservedBits);

  Selection mismatched;
  mismatched.data_select[1] = 1;
  EXPECT_EQ(encode(0, mismatched, storage.data(), layout, out).error.category(),
            ErrorCategory::kSelectionMismatch);
}

}  // namespace
}  // namespace rsg
