// Decoding frames straight into a struct, and encoding them from one, in one pass over the payload.
//
//   rsg::wire::FrameCodec codec(rsg::dds::robot_state_layout());   // one per stream; not thread-safe
//   const rsg::wire::DecodeResult result = codec.decode(datagram, &sample);
//   if (!result) { count(result.error().category()); return; }   // `sample` holds garbage: drop it
//
// The same checks and results as `decode` followed by `copy_fields`, and `encode`, but the copy
// and the CRC happen in the same pass over the bytes (see src/wire/internal/crc32_copy.hpp), which costs
// much less than two passes (measured in docs/benchmarks/wire.md). The codec keeps the copy plan
// of the last selection it saw.
#pragma once

#include <cstdint>
#include <span>

#include "rsg/wire/detail/copy_plan.hpp"
#include "rsg/wire/field_layout.hpp"
#include "rsg/wire/frame.hpp"

namespace rsg::wire {

class FrameCodec {
 public:
  /// `layout` describes the struct this codec fills and reads; it must outlive the codec.
  explicit FrameCodec(const FieldLayout& layout) noexcept;

  /// Validates `bytes` like `rsg::wire::decode` and, as it goes, copies the fields into the struct at
  /// `base` and zeroes the fields the frame does not carry. On failure the struct's field bytes
  /// are unspecified (part of the rejected frame may have landed there): never publish them.
  DecodeResult decode(std::span<const std::uint8_t> bytes, void* base) noexcept;

  /// `rsg::wire::encode` with this codec's layout.
  EncodeResult encode(std::uint8_t packet_number, const Selection& selection, const void* base,
                      std::span<std::uint8_t> out) noexcept;

 private:
  const detail::ChunkedCopyPlan& plan_for(const Selection& selection, std::uint64_t key) noexcept;
  void replan(const Selection& selection, std::uint64_t key) noexcept;

  const FieldLayout* layout_;
  detail::ChunkedCopyPlan plan_;
  std::uint64_t plan_key_;  // plan_'s selection as 7 header bytes
};

}  // namespace rsg::wire
