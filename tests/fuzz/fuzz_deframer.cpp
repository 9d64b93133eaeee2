// The deframer on an arbitrary stream, cut into chunks chosen by the input:
//
//   input = [n] [n chunk-size bytes] [stream...]   chunk k is sizes[k % n] + 1 bytes (n == 0: one chunk)
//
// Every frame handed out must be CRC-correct (checked with zlib, independently of ISA-L), must be
// the stream's bytes at the position the deframer has reached, and the chunking must not change
// what is found.
#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <vector>

#include "rsg/wire/deframer.hpp"
#include "tests/fuzz/fuzz_check.hpp"

namespace {

struct Outcome {
  std::vector<std::size_t> frame_sizes;
  std::uint64_t skipped_bytes = 0;
  std::size_t pending_bytes = 0;
  friend bool operator==(const Outcome&, const Outcome&) = default;
};

void require_correct_frame(std::span<const std::uint8_t> frame) {
  FUZZ_REQUIRE(frame.size() >= rsg::wire::kMinFrameBytes && frame.size() <= rsg::wire::kMaxFrameBytes);
  const std::size_t length = static_cast<std::size_t>(frame[1] | frame[2] << 8);
  FUZZ_REQUIRE(frame.size() == rsg::wire::kMinFrameBytes + length);
  const std::size_t covered = rsg::wire::kHeaderBytes + length;
  std::uint32_t trailer;
  std::memcpy(&trailer, frame.data() + covered, sizeof trailer);
  FUZZ_REQUIRE(trailer == ::crc32(0, frame.data(), static_cast<uInt>(covered)));
}

Outcome deframe(std::span<const std::uint8_t> stream, std::span<const std::uint8_t> chunk_sizes) {
  auto deframer = std::make_unique<rsg::wire::Deframer>();  // 4 KiB of buffer: keep it off the stack
  Outcome outcome;
  std::size_t consumed = 0;  // stream bytes accounted for: frames handed out plus bytes skipped
  std::size_t frame_bytes = 0;
  std::size_t chunk = 0;
  for (std::size_t fed = 0; fed < stream.size();) {
    const std::size_t wanted =
        chunk_sizes.empty() ? stream.size() : chunk_sizes[chunk++ % chunk_sizes.size()] + 1U;
    const std::size_t take = std::min(wanted, stream.size() - fed);
    deframer->feed(stream.subspan(fed, take), [&](std::span<const std::uint8_t> frame) {
      require_correct_frame(frame);
      consumed = frame_bytes + deframer->skipped_bytes();
      FUZZ_REQUIRE(consumed + frame.size() <= stream.size());
      FUZZ_REQUIRE(std::ranges::equal(frame, stream.subspan(consumed, frame.size())));
      frame_bytes += frame.size();
      outcome.frame_sizes.push_back(frame.size());
    });
    fed += take;
  }
  outcome.skipped_bytes = deframer->skipped_bytes();
  outcome.pending_bytes = deframer->pending_bytes();
  FUZZ_REQUIRE(deframer->frames() == outcome.frame_sizes.size());
  FUZZ_REQUIRE(frame_bytes + outcome.skipped_bytes + outcome.pending_bytes == stream.size());
  FUZZ_REQUIRE(outcome.pending_bytes < rsg::wire::kMaxFrameBytes);  // only a possible frame is held back
  return outcome;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::size_t plan_size = std::min<std::size_t>(data[0], size - 1);
  const std::span<const std::uint8_t> chunk_sizes(data + 1, plan_size);
  const std::span<const std::uint8_t> stream(data + 1 + plan_size, size - 1 - plan_size);
  FUZZ_REQUIRE(deframe(stream, chunk_sizes) == deframe(stream, {}));
  return 0;
}
