// The group filter class reads the same answer from a serialized sample as DDS-SQL gives on its
// members: for every group mask and every group_select, through the real type support's
// serialization (what a writer puts on the wire), and it refuses what it cannot vouch for.
#include "rsg/dds/group_filter.hpp"

#include <RobotStatePubSubTypes.h>
#include <gtest/gtest.h>

#include <vector>

#include "dds/internal/fastdds_compat.hpp"
#include "rsg/dds/views.hpp"

namespace rsg {
namespace {

std::vector<std::uint8_t> serialized(std::uint8_t group_select) {
  RobotState sample;
  sample.packet_number(7);
  sample.group_select(group_select);
  for (std::size_t g = 0; g < 6; ++g) sample.group_present()[g] = ((group_select >> g) & 1U) != 0;
  RobotStatePubSubType type;
  dds::rtps::SerializedPayload_t payload(dds::internal::max_serialized_size(type));
  EXPECT_TRUE(dds::internal::serialize(type, &sample, payload));
  return {payload.data, payload.data + payload.length};
}

TEST(GroupFilter, ParsesExactlyWhatGroupFilterExpressionWrites) {
  for (unsigned mask = 1; mask < 64; ++mask) {
    const auto parsed =
        dds::parse_group_filter_expression(dds::group_filter_expression(static_cast<std::uint8_t>(mask)));
    ASSERT_TRUE(parsed) << parsed.error();
    EXPECT_EQ(*parsed, mask);
  }
  const auto spaced =
      dds::parse_group_filter_expression("  group_present [ 4 ]=true and GROUP_PRESENT[0] = TRUE ");
  ASSERT_TRUE(spaced) << spaced.error();
  EXPECT_EQ(*spaced, 0b010001);
}

TEST(GroupFilter, RefusesEverythingElse) {
  for (const char* expression :
       {"", "group_present[6] = TRUE", "group_present[2] = FALSE",
        "group_present[2] = TRUE OR group_present[3] = TRUE", "group_present[2] = TRUE AND", "q[0] > 0.5",
        "group_present[%0] = TRUE", "group_present[2] = TRUE AND q[0] > 1"}) {
    const auto parsed = dds::parse_group_filter_expression(expression);
    EXPECT_FALSE(parsed) << expression;
    EXPECT_NE(parsed.error().find('"'), std::string::npos) << "the message quotes the expression";
  }
}

TEST(GroupFilter, AnswersFromTheSerializedSampleForEveryMaskAndSelection) {
  for (unsigned select = 0; select < 64; ++select) {
    const std::vector<std::uint8_t> bytes = serialized(static_cast<std::uint8_t>(select));
    for (unsigned mask = 1; mask < 64; ++mask)
      EXPECT_EQ(dds::payload_carries_groups(bytes, static_cast<std::uint8_t>(mask)), (select & mask) == mask)
          << "select " << select << " mask " << mask;
  }
}

TEST(GroupFilter, ReadsEveryEncodingRobotStateIsWrittenIn) {
  std::vector<std::uint8_t> bytes = serialized(0b001100);
  for (std::uint8_t id : {0x00, 0x01, 0x06, 0x07}) {  // CDR, PLAIN_CDR2, both endiannesses
    bytes[1] = id;
    EXPECT_TRUE(dds::payload_carries_groups(bytes, 0b001100));
    EXPECT_FALSE(dds::payload_carries_groups(bytes, 0b000001));
  }
  // DELIMITED_CDR2: a 4-byte length before the members.
  std::vector<std::uint8_t> delimited(bytes.begin(), bytes.begin() + 4);
  delimited[1] = 0x09;
  delimited.insert(delimited.end(), {0x10, 0, 0, 0});
  delimited.insert(delimited.end(), bytes.begin() + 4, bytes.end());
  EXPECT_TRUE(dds::payload_carries_groups(delimited, 0b001100));
}

TEST(GroupFilter, RefusesWhatItCannotVouchFor) {
  std::vector<std::uint8_t> bytes = serialized(0b111111);
  EXPECT_FALSE(dds::payload_carries_groups(std::span(bytes).first(5), 0b000001)) << "too short";
  EXPECT_FALSE(dds::payload_carries_groups({}, 0b000001));
  bytes[1] = 0x03;  // PL_CDR: parameter lists, never RobotState's encoding
  EXPECT_FALSE(dds::payload_carries_groups(bytes, 0b000001));
}

}  // namespace
}  // namespace rsg
