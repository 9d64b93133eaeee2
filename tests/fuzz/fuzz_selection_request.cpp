// Selection requests both ways on arbitrary bytes:
//  - decode_selection_request(): an accepted request is exactly what encode_selection_request()
//    writes, and a state decoder accepts it only when it selects no data;
//  - the input's first 8 bytes as (packet number, group_select, data_select[6]): a request that
//    encodes must decode to the same selection.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <span>

#include "rsg/wire/frame.hpp"
#include "tests/fuzz/fuzz_check.hpp"

namespace {

void check_decoding(std::span<const std::uint8_t> bytes) {
  const rsg::wire::SelectionRequestResult request = rsg::wire::decode_selection_request(bytes);
  if (!request) {
    FUZZ_REQUIRE(!request.error.message().empty());
    return;
  }
  std::array<std::uint8_t, rsg::wire::kSelectionRequestBytes> encoded{};
  const rsg::wire::EncodeResult reencoded =
      rsg::wire::encode_selection_request(request.packet_number, request.selection, encoded);
  FUZZ_REQUIRE(reencoded && reencoded.size == bytes.size());
  FUZZ_REQUIRE(std::ranges::equal(bytes, encoded));

  // docs/protocol.md: a state decoder rejects a request (length_mismatch) unless it selects nothing.
  const rsg::wire::DecodeResult state = rsg::wire::decode(bytes);
  if (request.selection.data_bytes() == 0)
    FUZZ_REQUIRE(state);
  else
    FUZZ_REQUIRE(!state && state.error().category() == rsg::wire::ErrorCategory::kLengthMismatch);
}

void check_encoding(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < 2 + rsg::wire::kGroupCount) return;
  rsg::wire::Selection selection;
  selection.group_select = bytes[1];
  std::memcpy(selection.data_select.data(), bytes.data() + 2, rsg::wire::kGroupCount);
  std::array<std::uint8_t, rsg::wire::kSelectionRequestBytes> encoded{};
  const rsg::wire::EncodeResult result = rsg::wire::encode_selection_request(bytes[0], selection, encoded);
  if (!result) {
    FUZZ_REQUIRE(result.size == 0 && !result.error.message().empty());
    return;
  }
  const rsg::wire::SelectionRequestResult request = rsg::wire::decode_selection_request(encoded);
  FUZZ_REQUIRE(request);
  FUZZ_REQUIRE(request.packet_number == bytes[0] && request.selection == selection);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  check_decoding(bytes);
  check_encoding(bytes);
  return 0;
}
