// The IDL RobotState mirrors the field table, stays plain/bounded/unkeyed, and each vector field
// lands in the member of the same name.
#include <RobotStatePubSubTypes.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "dds/internal/fastdds_compat.hpp"
#include "rsg/dds/robot_state.hpp"
#include "tests/support/vectors.hpp"

namespace rsg {
namespace {

TEST(RobotStateType, IsPlainBoundedAndUnkeyed) {
  RobotStatePubSubType type;
  EXPECT_TRUE(rsg::dds::internal::is_plain(type));
  EXPECT_TRUE(type.is_bounded());
  EXPECT_FALSE(rsg::dds::internal::is_keyed(type));
}

TEST(RobotStateType, MembersDoNotOverlap) {
  const wire::FieldLayout& layout = dds::robot_state_layout();
  for (std::size_t i = 1; i < wire::kFieldCount; ++i)
    EXPECT_GE(layout.offsets[i], layout.offsets[i - 1] + wire::kFields[i - 1].value_bytes())
        << wire::kFields[i].name;
  EXPECT_LE(layout.offsets.back() + wire::kFields.back().value_bytes(), sizeof(RobotState));
}

// Bytes of member `name` read through the generated accessor, not through our layout.
std::vector<std::byte> member_bytes(RobotState& sample, wire::Field field) {
  const std::byte* begin = nullptr;
  switch (field) {
#define RSG_MEMBER_CASE(name, index, group, mask, type, count, bytes) \
  case wire::Field::name:                                             \
    begin = reinterpret_cast<const std::byte*>(&sample.name());       \
    break;
    RSG_FIELDS(RSG_MEMBER_CASE)
#undef RSG_MEMBER_CASE
  }
  return {begin, begin + wire::info(field).value_bytes()};
}

TEST(RobotStateMapping, EachSingleFieldVectorLandsInItsOwnMember) {
  std::array<bool, wire::kFieldCount> covered{};
  for (const auto& vector : test::valid_vectors()) {
    const wire::DecodeResult result = wire::decode(vector.frame);
    ASSERT_TRUE(result);
    const wire::Selection& selection = result.frame().selection();
    int selected = 0;
    wire::Field only{};
    for (const wire::FieldInfo& field : wire::kFields)
      if (selection.contains(field.id())) ++selected, only = field.id();
    if (selected != 1) continue;
    covered[static_cast<std::size_t>(only)] = true;
    SCOPED_TRACE(wire::info(only).name);

    RobotState sample;
    // Poison every member, then decode into it.
    RobotState& poisoned = sample;
#define RSG_POISON(name, index, group, mask, type, count, bytes) \
  std::memset(static_cast<void*>(&poisoned.name()), 0x5A, wire::kFields[index].value_bytes());
    RSG_FIELDS(RSG_POISON)
#undef RSG_POISON
    dds::to_sample(result.frame(), poisoned);

    wire::StateValues expected;
    expected.assign(result.frame());
    for (const wire::FieldInfo& field : wire::kFields) {
      const auto bytes = member_bytes(poisoned, field.id());
      if (field.id() == only) {
        const auto* want =
            static_cast<const std::byte*>(wire::StateValues::layout().locate(expected.storage(), only));
        EXPECT_EQ(0, std::memcmp(bytes.data(), want, bytes.size()));
      } else {
        EXPECT_EQ(bytes, std::vector<std::byte>(bytes.size(), std::byte{0}))
            << "member " << field.name << " touched";
      }
    }
    EXPECT_EQ(poisoned.group_select(), selection.group_select);
    for (std::size_t g = 0; g < wire::kGroupCount; ++g)
      EXPECT_EQ(poisoned.group_present()[g], selection.has_group(g));
  }
  EXPECT_EQ(std::count(covered.begin(), covered.end(), true), 44) << "every field has a single-field vector";
}

TEST(RobotStateMapping, EveryVectorRoundTripsThroughTheSampleByteForByte) {
  for (const auto& vector : test::valid_vectors()) {
    const wire::DecodeResult result = wire::decode(vector.frame);
    ASSERT_TRUE(result);
    RobotState sample;
    dds::to_sample(result.frame(), sample);
    std::array<std::uint8_t, wire::kMaxFrameBytes> out{};
    const wire::EncodeResult encoded = dds::to_frame(sample, out);
    ASSERT_TRUE(encoded) << encoded.error.message();
    EXPECT_EQ(std::vector<std::uint8_t>(out.begin(), out.begin() + static_cast<long>(encoded.size)),
              vector.frame);
  }
}

TEST(RobotStateMapping, RefusesASampleNoFrameCouldCarry) {
  RobotState sample;
  sample.group_select(1 << 5);
  sample.data_select()[5] = 0x04;
  sample.robot_mode(9);
  std::array<std::uint8_t, wire::kMaxFrameBytes> out{};
  EXPECT_EQ(dds::to_frame(sample, out).error.category(), wire::ErrorCategory::kBadValue);
}

}  // namespace
}  // namespace rsg
