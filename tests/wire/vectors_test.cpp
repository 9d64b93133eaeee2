// Every conformance vector: decode by value, encode byte-exact, invalid category exact.
#include "tests/support/vectors.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "rsg/wire/crc32.hpp"
#include "rsg/wire/frame.hpp"
#include "rsg/wire/frame_codec.hpp"
#include "rsg/wire/json.hpp"
#include "rsg/wire/state_values.hpp"

namespace rsg {
namespace {

TEST(Vectors, AreAllThere) {
  EXPECT_EQ(test::valid_vectors().size(), 94U);
  EXPECT_EQ(test::load_vectors("invalid.jsonl", "error").size(), 29U);
  EXPECT_EQ(test::oversized_vectors().size(), 7U);
}

TEST(Vectors, ValidFramesDecodeToTheExpectedValues) {
  for (const auto& vector : test::valid_vectors()) {
    SCOPED_TRACE(vector.decoded_text.substr(0, 120));
    const wire::DecodeResult result = wire::decode(vector.frame);
    ASSERT_TRUE(result) << result.error().message();
    wire::StateValues decoded;
    decoded.assign(result.frame());

    const wire::Parsed<wire::StateValues> expected_parsed = wire::parse_canonical_json(vector.decoded_text);
    ASSERT_TRUE(expected_parsed) << expected_parsed.error();
    const wire::StateValues& expected = *expected_parsed;
    EXPECT_EQ(decoded, expected);  // bit-exact, so -0.0 keeps its sign

    // Our JSON says the same, compared by value as the spec asks.
    EXPECT_EQ(nlohmann::json::parse(wire::to_canonical_json(decoded)), vector.expected);
  }
}

TEST(Vectors, ValidFramesEncodeByteForByte) {
  for (const auto& vector : test::valid_vectors()) {
    SCOPED_TRACE(vector.decoded_text.substr(0, 120));
    const wire::Parsed<wire::StateValues> values_parsed = wire::parse_canonical_json(vector.decoded_text);
    ASSERT_TRUE(values_parsed) << values_parsed.error();
    const wire::StateValues& values = *values_parsed;
    std::array<std::uint8_t, wire::kMaxFrameBytes> out{};
    const wire::EncodeResult result =
        encode(values.packet_number, values.selection, values.storage(), wire::StateValues::layout(), out);
    ASSERT_TRUE(result) << result.error.message();
    EXPECT_EQ(std::vector<std::uint8_t>(out.begin(), out.begin() + static_cast<long>(result.size)),
              vector.frame);
  }
}

TEST(Vectors, InvalidFramesFailWithTheSpecCategory) {
  for (const auto& vector : test::invalid_vectors()) {
    const auto expected = wire::parse_error_category(vector.expected.get<std::string>());
    ASSERT_TRUE(expected.has_value());
    const wire::DecodeResult result = wire::decode(vector.frame);
    ASSERT_FALSE(result);
    EXPECT_EQ(result.error().category(), *expected)
        << "got " << wire::to_string(result.error().category()) << ": " << result.error().message();
    EXPECT_FALSE(result.error().message().empty());
  }
}

// The stitched decoder, one codec for all vectors so that its plan follows the selections.
TEST(Vectors, ValidFramesDecodeThroughFrameCodec) {
  wire::FrameCodec codec(wire::StateValues::layout());
  for (const auto& vector : test::valid_vectors()) {
    SCOPED_TRACE(vector.decoded_text.substr(0, 120));
    wire::StateValues decoded;
    std::memset(decoded.storage(), 0xA5, wire::StateValues::storage_size());  // stale values must not survive
    const wire::DecodeResult result = codec.decode(vector.frame, decoded.storage());
    ASSERT_TRUE(result) << result.error().message();
    decoded.packet_number = result.frame().packet_number();
    decoded.selection = result.frame().selection();
    const wire::Parsed<wire::StateValues> expected_parsed = wire::parse_canonical_json(vector.decoded_text);
    ASSERT_TRUE(expected_parsed) << expected_parsed.error();
    const wire::StateValues& expected = *expected_parsed;
    EXPECT_EQ(decoded, expected);
  }
}

TEST(Vectors, InvalidFramesFailThroughFrameCodecWithTheSpecCategory) {
  wire::FrameCodec codec(wire::StateValues::layout());
  for (const auto& vector : test::invalid_vectors()) {
    const auto expected = wire::parse_error_category(vector.expected.get<std::string>());
    ASSERT_TRUE(expected.has_value());
    wire::StateValues values;
    const wire::DecodeResult result = codec.decode(vector.frame, values.storage());
    ASSERT_FALSE(result);
    EXPECT_EQ(result.error().category(), *expected) << result.error().message();
  }
}

TEST(Crc32, MatchesTheZlibCheckValue) {
  const std::string check = "123456789";
  EXPECT_EQ(wire::crc32({reinterpret_cast<const std::uint8_t*>(check.data()), check.size()}), 0xCBF43926U);
}

}  // namespace
}  // namespace rsg
