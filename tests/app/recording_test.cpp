// The recording's schemas are the project's IDL files byte for byte, and a recorded payload is
// what Fast DDS itself puts on the wire; every conformance vector survives frame -> sample -> CDR
// -> sample -> frame unchanged (what rsg_replay relies on for byte-identical frames).
#include "app/recording.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "app/recording_schemas.hpp"
#include "rsg/dds/robot_state.hpp"
#include "tests/support/vectors.hpp"

namespace rsg::app {
namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST(RecordingSchemas, AreTheIdlFilesAsTheyAre) {
  EXPECT_EQ(schemas::kRobotStateIdl, read_text(RSG_SOURCE_DIR "/idl/RobotState.idl"));
  EXPECT_EQ(schemas::kGatewayStatusIdl, read_text(RSG_SOURCE_DIR "/idl/GatewayStatus.idl"));
}

TEST(RecordingProfile, NamesAreParsed) {
  EXPECT_EQ(parse_profile(""), Profile::omgidl);
  EXPECT_EQ(parse_profile("ros2"), Profile::ros2);
  EXPECT_FALSE(parse_profile("ros1"));
  EXPECT_TRUE(is_robot_state_schema("rsg::RobotState"));
  EXPECT_TRUE(is_robot_state_schema("rsg_msgs/msg/RobotState"));
  EXPECT_FALSE(is_robot_state_schema("rsg::GatewayStatus"));
}

TEST(RecordingCdr, EveryVectorRoundTripsToTheSameFrame) {
  CdrSerializer serializer;
  for (const auto& vector : test::valid_vectors()) {
    const wire::DecodeResult decoded = wire::decode(vector.frame);
    ASSERT_TRUE(decoded);
    RobotState sample;
    dds::to_sample(decoded.frame(), sample);
    const auto payload = serializer.serialize(sample);
    ASSERT_GE(payload.size(), 4u);
    EXPECT_EQ(payload[0], 0x00);  // encapsulation CDR_LE, as Fast DDS sends it
    EXPECT_EQ(payload[1], 0x01);
    const std::vector<std::uint8_t> bytes(payload.begin(), payload.end());
    RobotState back;
    ASSERT_TRUE(serializer.deserialize(bytes, back));
    std::array<std::uint8_t, wire::kMaxFrameBytes> out{};
    const wire::EncodeResult encoded = dds::to_frame(back, out);
    ASSERT_TRUE(encoded);
    EXPECT_EQ(std::vector<std::uint8_t>(out.begin(), out.begin() + static_cast<long>(encoded.size)),
              vector.frame);
  }
}

TEST(RecordingCdr, ShortOrForeignPayloadsAreRefused) {
  CdrSerializer serializer;
  RobotState sample;
  const auto payload = serializer.serialize(sample);
  std::vector<std::uint8_t> bytes(payload.begin(), payload.end());
  EXPECT_FALSE(serializer.deserialize(std::span(bytes).first(bytes.size() / 2), sample));
  bytes[1] = 0x42;  // no such encapsulation
  EXPECT_FALSE(serializer.deserialize(bytes, sample));
  EXPECT_FALSE(serializer.deserialize({}, sample));
}

}  // namespace
}  // namespace rsg::app
