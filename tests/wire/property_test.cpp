// Round trips over random selections and values: encode -> decode and JSON -> values are exact.
#include <gtest/gtest.h>

#include "rsg/wire/frame.hpp"
#include "rsg/wire/json.hpp"
#include "tests/support/random_state.hpp"

namespace rsg {
namespace {

constexpr int kRounds = 10'000;

TEST(Property, EncodeThenDecodeIsExact) {
  std::mt19937_64 rng(20261121);
  std::array<std::uint8_t, wire::kMaxFrameBytes> frame{};
  for (int round = 0; round < kRounds; ++round) {
    const wire::StateValues original = test::random_state(rng);
    const wire::EncodeResult encoded = encode(original.packet_number, original.selection, original.storage(),
                                              wire::StateValues::layout(), frame);
    ASSERT_TRUE(encoded) << encoded.error.message();
    ASSERT_EQ(encoded.size, wire::kMinFrameBytes + original.selection.data_bytes());
    const wire::DecodeResult decoded = wire::decode({frame.data(), encoded.size});
    ASSERT_TRUE(decoded) << decoded.error().message();
    wire::StateValues copy;
    copy.assign(decoded.frame());
    ASSERT_EQ(copy, original) << "round " << round;  // bitwise: NaN payloads and -0.0 survive
  }
}

TEST(Property, CanonicalJsonRoundTripsExactly) {
  std::mt19937_64 rng(7);
  for (int round = 0; round < kRounds; ++round) {
    const wire::StateValues original = test::random_state(rng, /*allow_nan_payloads=*/false);
    const std::string json = wire::to_canonical_json(original);
    const wire::Parsed<wire::StateValues> result = wire::parse_canonical_json(json);
    ASSERT_TRUE(result) << result.error() << "\n" << json;
    const wire::StateValues& parsed = *result;
    ASSERT_EQ(parsed, original) << json;
  }
}

TEST(Property, EveryCorruptedByteIsRejectedOrDecodesToTheSameBytes) {
  // A single flipped byte anywhere must never yield a "valid" frame with other content,
  // short of a CRC collision, which a single-byte change cannot produce.
  std::mt19937_64 rng(99);
  std::array<std::uint8_t, wire::kMaxFrameBytes> frame{};
  for (int round = 0; round < 500; ++round) {
    const wire::StateValues original = test::random_state(rng);
    const wire::EncodeResult encoded = encode(original.packet_number, original.selection, original.storage(),
                                              wire::StateValues::layout(), frame);
    ASSERT_TRUE(encoded);
    const std::size_t at = rng() % encoded.size;
    frame[at] ^= static_cast<std::uint8_t>(1 + rng() % 255);
    EXPECT_FALSE(wire::decode({frame.data(), encoded.size})) << "byte " << at;
  }
}

}  // namespace
}  // namespace rsg
