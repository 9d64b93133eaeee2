// The stitched CRC-and-copy kernel against ISA-L and memcpy, and FrameCodec against decode/encode.
//
// The kernel is held to the plain path bit for bit over random selections, random struct layouts
// (fields shuffled, with gaps) and random placements of frame and struct, including placements
// where its 64-byte accesses straddle a page boundary.
#include "rsg/frame_codec.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <numeric>
#include <random>
#include <vector>

#include "crc32_copy.hpp"
#include "random_state.hpp"
#include "rsg/copy_plan.hpp"
#include "rsg/crc32.hpp"
#include "rsg/frame.hpp"
#include "rsg/state_values.hpp"

namespace rsg {
namespace {

constexpr std::size_t kPage = 4096;

/// Page-aligned memory for frames and structs, so that tests can place them at chosen page offsets.
class Arena {
 public:
  explicit Arena(std::size_t pages) : bytes_(std::make_unique<std::byte[]>((pages + 1) * kPage)) {
    const auto address = reinterpret_cast<std::uintptr_t>(bytes_.get());
    aligned_ = bytes_.get() + (kPage - address % kPage) % kPage;
  }
  std::byte* at(std::size_t offset) { return aligned_ + offset; }

 private:
  std::unique_ptr<std::byte[]> bytes_;
  std::byte* aligned_;
};

Selection random_selection(std::mt19937_64& rng) {
  Selection selection;
  if (rng() % 3 == 0) return Selection::all();  // the usual frame, and the fast path
  for (std::size_t group = 0; group < kGroupCount; ++group) {
    if (rng() % 4 == 0) continue;
    selection.group_select |= static_cast<std::uint8_t>(1U << group);
    selection.data_select[group] = rng() % 2 ? 0xFF : static_cast<std::uint8_t>(rng());
  }
  selection.data_select[5] &= 0x0F;
  return selection;
}

/// Fields in a random order with random gaps: no kernel shortcut may assume field order.
FieldLayout random_layout(std::mt19937_64& rng, std::size_t& size) {
  std::array<std::size_t, kFieldCount> order{};
  std::iota(order.begin(), order.end(), 0);
  if (rng() % 2) std::shuffle(order.begin(), order.end(), rng);
  FieldLayout layout;
  std::uint32_t offset = 0;
  for (const std::size_t index : order) {
    if (rng() % 3 == 0) offset += static_cast<std::uint32_t>(rng() % 9);
    layout.offsets[index] = offset;
    offset += kFields[index].value_bytes();
  }
  size = offset;
  return layout;
}

void fill_random(std::span<std::byte> bytes, std::mt19937_64& rng) {
  for (std::byte& byte : bytes) byte = static_cast<std::byte>(rng());
}

class StitchedKernel : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!detail::has_stitched_crc32()) GTEST_SKIP() << "no AVX-512 VPCLMULQDQ on this CPU";
  }
};

TEST_F(StitchedKernel, ScatterMatchesIsalAndMemcpy) {
  std::mt19937_64 rng(20261121);
  Arena arena(4);
  for (int round = 0; round < 20'000; ++round) {
    const Selection selection = random_selection(rng);
    std::size_t struct_size = 0;
    const FieldLayout layout = random_layout(rng, struct_size);
    const ChunkedCopyPlan plan(selection, layout);
    const std::size_t frame_size = kHeaderBytes + selection.data_bytes();

    // Near a page end half of the time: the kernel's masked accesses must stay correct there.
    const std::size_t frame_at = rng() % 2 ? kPage - rng() % 128 : rng() % kPage;
    const std::size_t struct_at = 2 * kPage + (rng() % 2 ? kPage - rng() % 160 : rng() % kPage);
    const std::span frame(reinterpret_cast<std::uint8_t*>(arena.at(frame_at)), frame_size);
    fill_random(std::as_writable_bytes(frame), rng);
    std::vector<std::byte> expected(struct_size);
    fill_random(expected, rng);
    std::byte* actual = arena.at(struct_at);
    std::memcpy(actual, expected.data(), struct_size);

    const std::uint32_t expected_crc = detail::crc32_scatter_portable(frame, plan, expected.data());
    const std::uint32_t actual_crc = detail::crc32_scatter_stitched(frame, plan, actual);
    ASSERT_EQ(actual_crc, crc32(frame)) << "round " << round;
    ASSERT_EQ(actual_crc, expected_crc);
    ASSERT_EQ(std::memcmp(actual, expected.data(), struct_size), 0) << "round " << round;
  }
}

TEST_F(StitchedKernel, GatherMatchesMemcpyAndIsal) {
  std::mt19937_64 rng(7);
  Arena arena(4);
  std::vector<std::uint8_t> expected(kMaxFrameBytes + 128);  // the frame and 64 bytes either side
  for (int round = 0; round < 20'000; ++round) {
    const Selection selection = random_selection(rng);
    std::size_t struct_size = 0;
    const FieldLayout layout = random_layout(rng, struct_size);
    const ChunkedCopyPlan plan(selection, layout);
    const std::size_t frame_size = kHeaderBytes + selection.data_bytes();

    const std::size_t struct_at = rng() % 2 ? kPage - rng() % 160 : rng() % kPage;
    const std::size_t frame_at = 2 * kPage + (rng() % 2 ? kPage - rng() % 128 : rng() % kPage);
    fill_random({arena.at(struct_at), struct_size}, rng);
    // The bytes around the frame must stay untouched.
    const std::span around(reinterpret_cast<std::uint8_t*>(arena.at(frame_at - 64)), frame_size + 128);
    fill_random(std::as_writable_bytes(around), rng);
    const std::span frame = around.subspan(64, frame_size);
    std::copy(around.begin(), around.end(), expected.begin());
    const std::span expected_frame = std::span(expected).subspan(64, frame_size);

    const std::uint32_t expected_crc =
        detail::gather_crc32_portable(expected_frame, plan, arena.at(struct_at));
    const std::uint32_t actual_crc = detail::gather_crc32_stitched(frame, plan, arena.at(struct_at));
    ASSERT_EQ(actual_crc, expected_crc) << "round " << round;
    ASSERT_TRUE(std::equal(around.begin(), around.end(), expected.begin())) << "round " << round;
  }
}

TEST_F(StitchedKernel, EveryFrameLengthAndPadding) {
  // A contiguous layout with the full selection, cut short: every length the kernel takes, so every
  // head padding 0..63 and every way the frame's first four bytes fall across the first chunks.
  std::mt19937_64 rng(3);
  std::vector<std::uint8_t> frame(kMaxFrameBytes);
  for (std::uint8_t& byte : frame) byte = static_cast<std::uint8_t>(rng());
  StateValues values;
  for (std::size_t size = 256; size <= kMaxFrameBytes; ++size) {
    // A selection whose frame is `size` bytes does not exist for every size; the kernel itself
    // works on any plan whose padding fits, which is what this checks, with the plan's moves unused.
    const ChunkedCopyPlan plan(Selection{}, StateValues::layout());
    const std::span covered = std::span(frame).first(size);
    if ((size + plan.head_padding()) % kChunkBytes != 0) {
      EXPECT_EQ(detail::crc32_scatter_stitched(covered, plan, static_cast<std::byte*>(values.storage())),
                crc32(covered));  // falls back to the plain path
      continue;
    }
    EXPECT_EQ(detail::crc32_scatter_stitched(covered, plan, static_cast<std::byte*>(values.storage())),
              crc32(covered));
  }
}

TEST(CopyPlan, FullSelectionIsAFewMovesAndLeavesOnlyErrorSetHighBytes) {
  const CopyPlan plan(Selection::all(), StateValues::layout());
  // StateValues stores fields in table order; the two 5-byte error sets widen to 8 bytes, which
  // shifts what follows each: the doubles with current_errors, last_motion_errors, the rest.
  EXPECT_EQ(plan.moves().size(), 3U);
  ASSERT_EQ(plan.fills().size(), 2U);
  EXPECT_EQ(plan.fills()[0].size, 3U);
  EXPECT_EQ(plan.fills()[1].size, 3U);
  EXPECT_EQ(plan.covered_bytes(), kHeaderBytes + kMaxDataBytes);
  const ChunkedCopyPlan chunked(Selection::all(), StateValues::layout());
  EXPECT_EQ((plan.covered_bytes() + chunked.head_padding()) % kChunkBytes, 0U);
}

TEST(CopyPlan, EmptySelectionZeroesEverything) {
  const CopyPlan plan(Selection{}, StateValues::layout());
  EXPECT_TRUE(plan.moves().empty());
  ASSERT_EQ(plan.fills().size(), 1U);
  EXPECT_EQ(plan.fills()[0].size, StateValues::storage_size());
}

TEST(FrameCodec, DecodesLikeDecodeThenCopyFields) {
  std::mt19937_64 rng(11);
  FrameCodec codec(StateValues::layout());
  std::array<std::uint8_t, kMaxFrameBytes> frame{};
  for (int round = 0; round < 5'000; ++round) {
    const StateValues original = test::random_state(rng);
    const EncodeResult encoded =
        encode(original.packet_number, original.selection, original.storage(), StateValues::layout(), frame);
    ASSERT_TRUE(encoded) << encoded.error.message();
    const std::span bytes = std::span(frame).first(encoded.size);

    StateValues stale;  // a reused sample: every byte must be rewritten
    std::memset(stale.storage(), 0x5A, StateValues::storage_size());
    const DecodeResult decoded = codec.decode(bytes, stale.storage());
    ASSERT_TRUE(decoded) << decoded.error().message();
    stale.packet_number = decoded.frame().packet_number();
    stale.selection = decoded.frame().selection();
    ASSERT_EQ(stale, original) << "round " << round;
  }
}

TEST(FrameCodec, RejectsWhatDecodeRejectsWithTheSameCategory) {
  std::mt19937_64 rng(12);
  FrameCodec codec(StateValues::layout());
  std::array<std::uint8_t, kMaxFrameBytes> frame{};
  for (int round = 0; round < 5'000; ++round) {
    const StateValues original = test::random_state(rng);
    const EncodeResult encoded =
        encode(original.packet_number, original.selection, original.storage(), StateValues::layout(), frame);
    ASSERT_TRUE(encoded);
    std::size_t size = encoded.size;
    switch (rng() % 3) {
      case 0:  // a corrupted byte anywhere: header, data or trailer
        frame[rng() % size] ^= static_cast<std::uint8_t>(1 + rng() % 255);
        break;
      case 1:  // cut short or padded
        size = rng() % 2 ? size - 1 - rng() % size : std::min(size + 1 + rng() % 8, frame.size());
        break;
      default:  // a header byte replaced, CRC still over the original bytes
        frame[rng() % kHeaderBytes] = static_cast<std::uint8_t>(rng());
        break;
    }
    const std::span bytes = std::span(frame).first(size);
    const DecodeResult plain = decode(bytes);
    StateValues values;
    const DecodeResult stitched = codec.decode(bytes, values.storage());
    ASSERT_EQ(static_cast<bool>(stitched), static_cast<bool>(plain)) << "round " << round;
    ASSERT_EQ(stitched.error().category(), plain.error().category())
        << "round " << round << ": " << stitched.error().message() << " / " << plain.error().message();
  }
}

TEST(FrameCodec, EncodesLikeEncodeAndRefusesTheSameValues) {
  std::mt19937_64 rng(13);
  FrameCodec codec(StateValues::layout());
  std::array<std::uint8_t, kMaxFrameBytes> expected{};
  std::array<std::uint8_t, kMaxFrameBytes> actual{};
  for (int round = 0; round < 2'000; ++round) {
    StateValues values = test::random_state(rng);
    if (round % 10 == 0 && values.selection.contains(Field::robot_mode))
      values.set_integer(Field::robot_mode, 7);
    if (round % 10 == 1 && values.selection.contains(Field::current_errors))
      values.set_integer(Field::current_errors, std::uint64_t{1} << 38);
    const EncodeResult plain =
        encode(values.packet_number, values.selection, values.storage(), StateValues::layout(), expected);
    const EncodeResult stitched =
        codec.encode(values.packet_number, values.selection, values.storage(), actual);
    ASSERT_EQ(stitched.size, plain.size);
    ASSERT_EQ(stitched.error.category(), plain.error.category());
    ASSERT_TRUE(
        std::equal(actual.begin(), actual.begin() + static_cast<long>(stitched.size), expected.begin()));
    if (stitched) {
      ASSERT_TRUE(decode(std::span(actual).first(stitched.size))) << "round " << round;
    }
  }
}

}  // namespace
}  // namespace rsg
