#include "rsg/wire/frame_codec.hpp"

#include "rsg/wire/crc32.hpp"
#include "wire/internal/crc32_copy.hpp"
#include "wire/internal/frame_checks.hpp"

namespace rsg::wire {

FrameCodec::FrameCodec(const FieldLayout& layout) noexcept
    : layout_(&layout), plan_(Selection{}, layout), plan_key_(internal::selection_key(Selection{})) {}

const detail::ChunkedCopyPlan& FrameCodec::plan_for(const Selection& selection, std::uint64_t key) noexcept {
  if (key != plan_key_) replan(selection, key);
  return plan_;
}

// Out of line: the plan under construction takes kilobytes of stack, which the per-frame path
// should not have to set up.
[[gnu::noinline]] void FrameCodec::replan(const Selection& selection, std::uint64_t key) noexcept {
  plan_ = detail::ChunkedCopyPlan(selection, *layout_);
  plan_key_ = key;
}

DecodeResult FrameCodec::decode(std::span<const std::uint8_t> bytes, void* base) noexcept {
  return internal::FrameDecoder::decode(
      bytes, [&](std::span<const std::uint8_t> covered, const Selection* selection) {
        if (selection == nullptr) return crc32(covered);
        const detail::ChunkedCopyPlan& plan = plan_for(*selection, internal::selection_key(covered));
        internal::zero_fills(plan.plan(), base);
        return internal::crc32_scatter(covered, plan, static_cast<std::byte*>(base));
      });
}

EncodeResult FrameCodec::encode(std::uint8_t packet_number, const Selection& selection, const void* base,
                                std::span<std::uint8_t> out) noexcept {
  EncodeResult result;
  const std::size_t covered =
      internal::begin_encode(packet_number, selection, base, *layout_, out, result.error);
  if (covered == 0) return result;
  const std::uint32_t crc =
      internal::gather_crc32(out.first(covered), plan_for(selection, internal::selection_key(selection)),
                             static_cast<const std::byte*>(base));
  result.size = internal::finish_encode(out, covered, crc);
  return result;
}

}  // namespace rsg::wire
