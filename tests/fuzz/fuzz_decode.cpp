// decode() on arbitrary bytes. A frame it accepts must be exactly what encode() writes for the
// values it carries. FrameCodec, which copies in the CRC pass, must reach the same verdict and the
// same values.
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>

#include "rsg/wire/frame.hpp"
#include "rsg/wire/frame_codec.hpp"
#include "rsg/wire/state_values.hpp"
#include "tests/fuzz/fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  const rsg::wire::DecodeResult result = rsg::wire::decode(bytes);
  rsg::wire::StateValues stitched;
  rsg::wire::FrameCodec codec(rsg::wire::StateValues::layout());
  const rsg::wire::DecodeResult stitched_result = codec.decode(bytes, stitched.storage());
  FUZZ_REQUIRE(stitched_result.error().category() == result.error().category());
  if (!result) {
    FUZZ_REQUIRE(result.error().category() != rsg::wire::ErrorCategory::kNone);
    FUZZ_REQUIRE(!result.error().message().empty());
    return 0;
  }

  rsg::wire::StateValues values;
  values.assign(result.frame());
  stitched.packet_number = stitched_result.frame().packet_number();
  stitched.selection = stitched_result.frame().selection();
  FUZZ_REQUIRE(stitched == values);
  std::array<std::uint8_t, rsg::wire::kMaxFrameBytes> encoded{};
  const rsg::wire::EncodeResult reencoded = rsg::wire::encode(
      values.packet_number, values.selection, values.storage(), rsg::wire::StateValues::layout(), encoded);
  FUZZ_REQUIRE(reencoded);
  FUZZ_REQUIRE(reencoded.size == bytes.size());
  FUZZ_REQUIRE(std::equal(bytes.begin(), bytes.end(), encoded.begin()));
  return 0;
}
