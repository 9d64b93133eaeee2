// parse_canonical_json() on arbitrary text. An object it accepts and encode() takes must survive
// encode -> decode -> to_canonical_json -> parse bit for bit, and its canonical text is a fixed point.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "rsg/wire/frame.hpp"
#include "rsg/wire/json.hpp"
#include "rsg/wire/state_values.hpp"
#include "tests/fuzz/fuzz_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const rsg::wire::Parsed<rsg::wire::StateValues> result = rsg::wire::parse_canonical_json(text);
  if (!result) {
    FUZZ_REQUIRE(!result.error().empty());
    return 0;
  }
  const rsg::wire::StateValues& parsed = *result;

  std::array<std::uint8_t, rsg::wire::kMaxFrameBytes> frame{};
  const rsg::wire::EncodeResult encoded = rsg::wire::encode(
      parsed.packet_number, parsed.selection, parsed.storage(), rsg::wire::StateValues::layout(), frame);
  if (!encoded) return 0;  // parsing takes e.g. robot_mode 7 or reserved bits, which no frame may carry

  const rsg::wire::DecodeResult decoded = rsg::wire::decode(std::span(frame).first(encoded.size));
  FUZZ_REQUIRE(decoded);
  rsg::wire::StateValues values;
  values.assign(decoded.frame());
  FUZZ_REQUIRE(values == parsed);  // NaN from JSON is the canonical quiet NaN, so bits match too

  const std::string canonical = rsg::wire::to_canonical_json(values);
  const rsg::wire::Parsed<rsg::wire::StateValues> reparsed = rsg::wire::parse_canonical_json(canonical);
  FUZZ_REQUIRE(reparsed);
  FUZZ_REQUIRE(*reparsed == values);
  FUZZ_REQUIRE(rsg::wire::to_canonical_json(*reparsed) == canonical);
  return 0;
}
