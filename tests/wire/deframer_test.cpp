// The stream deframer finds every frame however the stream is chunked and skips garbage.
#include "rsg/wire/deframer.hpp"

#include <gtest/gtest.h>

#include "rsg/wire/frame.hpp"
#include "tests/support/random_state.hpp"

namespace rsg {
namespace {

std::vector<std::uint8_t> encode_state(const wire::StateValues& values) {
  std::vector<std::uint8_t> frame(wire::kMaxFrameBytes);
  const wire::EncodeResult result =
      encode(values.packet_number, values.selection, values.storage(), wire::StateValues::layout(), frame);
  frame.resize(result.size);
  return frame;
}

struct Stream {
  std::vector<std::uint8_t> bytes;
  std::vector<std::vector<std::uint8_t>> frames;
  std::size_t garbage = 0;
};

Stream make_stream(std::mt19937_64& rng, int frames, bool with_garbage) {
  Stream stream;
  for (int i = 0; i < frames; ++i) {
    if (with_garbage && rng() % 2) {
      const std::size_t count = rng() % 40;
      for (std::size_t k = 0; k < count; ++k) {
        // Avoid 0x3X so every garbage byte is provably skipped exactly once.
        std::uint8_t byte = static_cast<std::uint8_t>(rng());
        if ((byte & 0xF0) == 0x30) byte ^= 0x80;
        stream.bytes.push_back(byte);
      }
      stream.garbage += count;
    }
    auto frame = encode_state(test::random_state(rng));
    stream.bytes.insert(stream.bytes.end(), frame.begin(), frame.end());
    stream.frames.push_back(std::move(frame));
  }
  return stream;
}

std::vector<std::vector<std::uint8_t>> feed_in_chunks(wire::Deframer& deframer,
                                                      const std::vector<std::uint8_t>& bytes,
                                                      std::mt19937_64& rng, std::size_t max_chunk) {
  std::vector<std::vector<std::uint8_t>> found;
  std::size_t at = 0;
  while (at < bytes.size()) {
    const std::size_t size = std::min<std::size_t>(1 + rng() % max_chunk, bytes.size() - at);
    deframer.feed({bytes.data() + at, size}, [&](std::span<const std::uint8_t> frame) {
      found.emplace_back(frame.begin(), frame.end());
    });
    at += size;
  }
  return found;
}

TEST(Deframer, FindsEveryFrameInArbitraryChunks) {
  std::mt19937_64 rng(1);
  for (std::size_t max_chunk : {1UL, 7UL, 100UL, 3000UL, 100000UL}) {
    const Stream stream = make_stream(rng, 50, false);
    wire::Deframer deframer;
    EXPECT_EQ(feed_in_chunks(deframer, stream.bytes, rng, max_chunk), stream.frames) << "chunk " << max_chunk;
    EXPECT_EQ(deframer.skipped_bytes(), 0U);
    EXPECT_EQ(deframer.pending_bytes(), 0U);
  }
}

TEST(Deframer, ResynchronisesAfterGarbageAndCountsIt) {
  std::mt19937_64 rng(2);
  const Stream stream = make_stream(rng, 200, true);
  wire::Deframer deframer;
  const auto found = feed_in_chunks(deframer, stream.bytes, rng, 500);
  EXPECT_EQ(found, stream.frames);
  EXPECT_EQ(deframer.skipped_bytes(), stream.garbage);
  EXPECT_EQ(deframer.frames(), stream.frames.size());
}

TEST(Deframer, SkipsAFrameWithABadCrcAndFindsTheNext) {
  std::mt19937_64 rng(3);
  const Stream stream = make_stream(rng, 3, false);
  auto bytes = stream.bytes;
  bytes[stream.frames[0].size() - 1] ^= 0xFF;  // first frame's CRC
  wire::Deframer deframer;
  const auto found = feed_in_chunks(deframer, bytes, rng, 64);
  ASSERT_EQ(found.size(), 2U);
  EXPECT_EQ(found[0], stream.frames[1]);
  EXPECT_EQ(found[1], stream.frames[2]);
  EXPECT_GE(deframer.skipped_bytes(), stream.frames[0].size() - 1);  // may stall on a false header inside
}

TEST(Deframer, HoldsBackAPartialFrame) {
  std::mt19937_64 rng(4);
  const Stream stream = make_stream(rng, 1, false);
  wire::Deframer deframer;
  int frames = 0;
  deframer.feed({stream.bytes.data(), stream.bytes.size() - 1}, [&](auto) { ++frames; });
  EXPECT_EQ(frames, 0);
  EXPECT_EQ(deframer.pending_bytes(), stream.bytes.size() - 1);
  deframer.feed({&stream.bytes.back(), 1}, [&](auto) { ++frames; });
  EXPECT_EQ(frames, 1);
}

}  // namespace
}  // namespace rsg
