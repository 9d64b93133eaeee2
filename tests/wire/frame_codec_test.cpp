// The stitched CRC-and-copy kernel against ISA-L and memcpy, and FrameCodec against decode/encode.
//
// The kernel is held to the plain path bit for bit over random selections, random struct layouts
// (fields shuffled, with gaps) and random placements of frame and struct, including placements
// where its 64-byte accesses straddle a page boundary.
#include "rsg/wire/frame_codec.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <numeric>
#include <random>
#include <set>
#include <vector>

#include "rsg/wire/crc32.hpp"
#include "rsg/wire/detail/copy_plan.hpp"
#include "rsg/wire/frame.hpp"
#include "rsg/wire/state_values.hpp"
#include "tests/support/random_state.hpp"
#include "wire/internal/crc32_copy.hpp"

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

wire::Selection random_selection(std::mt19937_64& rng) {
  wire::Selection selection;
  if (rng() % 3 == 0) return wire::Selection::all();  // the usual frame, and the fast path
  for (std::size_t group = 0; group < wire::kGroupCount; ++group) {
    if (rng() % 4 == 0) continue;
    selection.group_select |= static_cast<std::uint8_t>(1U << group);
    selection.data_select[group] = rng() % 2 ? 0xFF : static_cast<std::uint8_t>(rng());
  }
  selection.data_select[5] &= 0x0F;
  return selection;
}

/// Fields in a random order with random gaps: no kernel shortcut may assume field order.
wire::FieldLayout random_layout(std::mt19937_64& rng, std::size_t& size) {
  std::array<std::size_t, wire::kFieldCount> order{};
  std::iota(order.begin(), order.end(), 0);
  if (rng() % 2) std::shuffle(order.begin(), order.end(), rng);
  wire::FieldLayout layout;
  std::uint32_t offset = 0;
  for (const std::size_t index : order) {
    if (rng() % 3 == 0) offset += static_cast<std::uint32_t>(rng() % 9);
    layout.offsets[index] = offset;
    offset += wire::kFields[index].value_bytes();
  }
  size = offset;
  return layout;
}

void fill_random(std::span<std::byte> bytes, std::mt19937_64& rng) {
  for (std::byte& byte : bytes) byte = static_cast<std::byte>(rng());
}

/// The CRC-and-copy kernel this CPU runs (the stitched AVX-512 one where has_stitched_crc32(), the
/// portable one elsewhere: the stitched one cannot run without AVX-512), checked against references
/// that share nothing with either: ISA-L's CRC of the whole frame and one memcpy per move.
class CrcCopyKernel : public ::testing::Test {
 protected:
  void SetUp() override {
    RecordProperty("kernel", wire::internal::has_stitched_crc32() ? "stitched (AVX-512)" : "portable");
  }
};

/// A random kernel input: selection, layout and plan, a frame and a struct placed near a page end
/// half of the time (where the kernel's masked accesses must still be exact), and a copy of the
/// destination with 64 bytes either side, which the plain path works on for comparison.
class KernelCase {
 public:
  static constexpr std::size_t kMargin = 64;

  KernelCase(std::mt19937_64& rng, Arena& arena, bool struct_is_destination)
      : selection_(random_selection(rng)),
        layout_(random_layout(rng, struct_size_)),
        plan_(selection_, layout_),
        frame_(reinterpret_cast<std::uint8_t*>(arena.at(kPage + anywhere_or_at_page_end(rng, 128))),
               wire::kHeaderBytes + selection_.data_bytes()),
        struct_(arena.at(4 * kPage + anywhere_or_at_page_end(rng, 160)), struct_size_),
        destination_(struct_is_destination ? struct_ : std::as_writable_bytes(frame_)) {
    fill_random({reinterpret_cast<std::byte*>(frame_.data()) - kMargin, frame_.size() + 2 * kMargin}, rng);
    fill_random({struct_.data() - kMargin, struct_.size() + 2 * kMargin}, rng);
    expected_.assign(destination_.data() - kMargin, destination_.data() + destination_.size() + kMargin);
  }

  const wire::detail::ChunkedCopyPlan& plan() const { return plan_; }
  std::span<std::uint8_t> frame() { return frame_; }
  std::byte* struct_base() { return struct_.data(); }
  /// The destination as the plain path sees it: inside the copy.
  std::span<std::uint8_t> expected_frame() {
    return {reinterpret_cast<std::uint8_t*>(expected_.data() + kMargin), frame_.size()};
  }
  std::byte* expected_struct() { return expected_.data() + kMargin; }
  /// Whether the destination and its margins now equal the copy.
  bool same_as_expected() const {
    return std::equal(expected_.begin(), expected_.end(), destination_.data() - kMargin);
  }

 private:
  static std::size_t anywhere_or_at_page_end(std::mt19937_64& rng, std::size_t reach) {
    return rng() % 2 ? kPage - rng() % reach : rng() % kPage;
  }

  wire::Selection selection_;
  std::size_t struct_size_ = 0;
  wire::FieldLayout layout_;
  wire::detail::ChunkedCopyPlan plan_;
  std::span<std::uint8_t> frame_;
  std::span<std::byte> struct_;
  std::span<std::byte> destination_;
  std::vector<std::byte> expected_;
};

TEST_F(CrcCopyKernel, ScatterMatchesIsalAndMemcpy) {
  std::mt19937_64 rng(20261121);
  Arena arena(8);
  for (int round = 0; round < 20'000; ++round) {
    KernelCase input(rng, arena, /*struct_is_destination=*/true);
    wire::internal::copy_to_struct(input.frame(), input.plan().plan(), input.expected_struct());
    const std::uint32_t actual =
        wire::internal::crc32_scatter(input.frame(), input.plan(), input.struct_base());
    ASSERT_EQ(actual, wire::crc32(input.frame())) << "round " << round;
    ASSERT_TRUE(input.same_as_expected()) << "round " << round;
  }
}

TEST_F(CrcCopyKernel, GatherMatchesMemcpyAndIsal) {
  std::mt19937_64 rng(7);
  Arena arena(8);
  for (int round = 0; round < 20'000; ++round) {
    KernelCase input(rng, arena, /*struct_is_destination=*/false);
    wire::internal::copy_to_frame(input.expected_frame(), input.plan().plan(), input.struct_base());
    const std::uint32_t actual =
        wire::internal::gather_crc32(input.frame(), input.plan(), input.struct_base());
    ASSERT_EQ(actual, wire::crc32(input.expected_frame())) << "round " << round;
    ASSERT_EQ(actual, wire::crc32(input.frame()));
    ASSERT_TRUE(input.same_as_expected()) << "round " << round;
  }
}

TEST_F(CrcCopyKernel, EveryHeadPaddingASelectionCanHave) {
  // The padding in front of the first chunk is 64 minus the frame's length mod 64, so it follows
  // the selection. Field sizes are multiples of 8 plus the 5-, 5- and 1-byte fields, so not every
  // padding occurs; visit each one that does, with paddings 61 and 62, where the frame's first four
  // bytes (the inverted start of the CRC) straddle the first two chunks, among them.
  std::mt19937_64 rng(3);
  std::array<std::uint8_t, wire::kMaxFrameBytes> frame{};
  std::set<std::size_t> paddings;
  for (int round = 0; round < 200'000; ++round) {
    const wire::Selection selection = random_selection(rng);
    const wire::detail::ChunkedCopyPlan plan(selection, wire::StateValues::layout());
    const std::size_t size = plan.plan().covered_bytes();
    if (size < 256 || !paddings.insert(plan.head_padding()).second) continue;

    const std::span covered = std::span(frame).first(size);
    for (std::uint8_t& byte : covered) byte = static_cast<std::uint8_t>(rng());
    wire::StateValues expected;
    wire::StateValues actual;
    EXPECT_EQ(wire::internal::crc32_scatter(covered, plan, static_cast<std::byte*>(actual.storage())),
              wire::crc32(covered))
        << "padding " << plan.head_padding();
    wire::internal::copy_to_struct(covered, plan.plan(), static_cast<std::byte*>(expected.storage()));
    EXPECT_EQ(std::memcmp(actual.storage(), expected.storage(), wire::StateValues::storage_size()), 0)
        << "padding " << plan.head_padding();
  }
  EXPECT_TRUE(paddings.contains(61) && paddings.contains(62));
  EXPECT_EQ(paddings.size(), 48U);  // 6 of the 8 residues mod 8, times 8
}

TEST(CopyPlan, FullSelectionIsAFewMovesAndLeavesOnlyErrorSetHighBytes) {
  const wire::detail::CopyPlan plan(wire::Selection::all(), wire::StateValues::layout());
  // StateValues stores fields in table order; the two 5-byte error sets widen to 8 bytes, which
  // shifts what follows each: the doubles with current_errors, last_motion_errors, the rest.
  EXPECT_EQ(plan.moves().size(), 3U);
  ASSERT_EQ(plan.fills().size(), 2U);
  EXPECT_EQ(plan.fills()[0].size, 3U);
  EXPECT_EQ(plan.fills()[1].size, 3U);
  EXPECT_EQ(plan.covered_bytes(), wire::kHeaderBytes + wire::kMaxDataBytes);
  const wire::detail::ChunkedCopyPlan chunked(wire::Selection::all(), wire::StateValues::layout());
  EXPECT_EQ((plan.covered_bytes() + chunked.head_padding()) % wire::detail::kChunkBytes, 0U);
}

TEST(CopyPlan, EmptySelectionZeroesEverything) {
  const wire::detail::CopyPlan plan(wire::Selection{}, wire::StateValues::layout());
  EXPECT_TRUE(plan.moves().empty());
  ASSERT_EQ(plan.fills().size(), 1U);
  EXPECT_EQ(plan.fills()[0].size, wire::StateValues::storage_size());
}

TEST(FrameCodec, DecodesLikeDecodeThenCopyFields) {
  std::mt19937_64 rng(11);
  wire::FrameCodec codec(wire::StateValues::layout());
  std::array<std::uint8_t, wire::kMaxFrameBytes> frame{};
  for (int round = 0; round < 5'000; ++round) {
    const wire::StateValues original = test::random_state(rng);
    const wire::EncodeResult encoded = encode(original.packet_number, original.selection, original.storage(),
                                              wire::StateValues::layout(), frame);
    ASSERT_TRUE(encoded) << encoded.error.message();
    const std::span bytes = std::span(frame).first(encoded.size);

    wire::StateValues stale;  // a reused sample: every byte must be rewritten
    std::memset(stale.storage(), 0x5A, wire::StateValues::storage_size());
    const wire::DecodeResult decoded = codec.decode(bytes, stale.storage());
    ASSERT_TRUE(decoded) << decoded.error().message();
    stale.packet_number = decoded.frame().packet_number();
    stale.selection = decoded.frame().selection();
    ASSERT_EQ(stale, original) << "round " << round;
  }
}

TEST(FrameCodec, RejectsWhatDecodeRejectsWithTheSameCategory) {
  std::mt19937_64 rng(12);
  wire::FrameCodec codec(wire::StateValues::layout());
  std::array<std::uint8_t, wire::kMaxFrameBytes> frame{};
  for (int round = 0; round < 5'000; ++round) {
    const wire::StateValues original = test::random_state(rng);
    const wire::EncodeResult encoded = encode(original.packet_number, original.selection, original.storage(),
                                              wire::StateValues::layout(), frame);
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
        frame[rng() % wire::kHeaderBytes] = static_cast<std::uint8_t>(rng());
        break;
    }
    const std::span bytes = std::span(frame).first(size);
    const wire::DecodeResult plain = wire::decode(bytes);
    wire::StateValues values;
    const wire::DecodeResult stitched = codec.decode(bytes, values.storage());
    ASSERT_EQ(static_cast<bool>(stitched), static_cast<bool>(plain)) << "round " << round;
    ASSERT_EQ(stitched.error().category(), plain.error().category())
        << "round " << round << ": " << stitched.error().message() << " / " << plain.error().message();
  }
}

TEST(FrameCodec, EncodesLikeEncodeAndRefusesTheSameValues) {
  std::mt19937_64 rng(13);
  wire::FrameCodec codec(wire::StateValues::layout());
  std::array<std::uint8_t, wire::kMaxFrameBytes> expected{};
  std::array<std::uint8_t, wire::kMaxFrameBytes> actual{};
  for (int round = 0; round < 2'000; ++round) {
    wire::StateValues values = test::random_state(rng);
    if (round % 10 == 0 && values.selection.contains(wire::Field::robot_mode))
      values.set_integer(wire::Field::robot_mode, 7);
    if (round % 10 == 1 && values.selection.contains(wire::Field::current_errors))
      values.set_integer(wire::Field::current_errors, std::uint64_t{1} << 38);
    const wire::EncodeResult plain = encode(values.packet_number, values.selection, values.storage(),
                                            wire::StateValues::layout(), expected);
    const wire::EncodeResult stitched =
        codec.encode(values.packet_number, values.selection, values.storage(), actual);
    ASSERT_EQ(stitched.size, plain.size);
    ASSERT_EQ(stitched.error.category(), plain.error.category());
    ASSERT_TRUE(
        std::equal(actual.begin(), actual.begin() + static_cast<long>(stitched.size), expected.begin()));
    if (stitched) {
      ASSERT_TRUE(wire::decode(std::span(actual).first(stitched.size))) << "round " << round;
    }
  }
}

}  // namespace
}  // namespace rsg
