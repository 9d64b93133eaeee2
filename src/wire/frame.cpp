#include "rsg/wire/frame.hpp"

#include <cstring>

#include "rsg/wire/crc32.hpp"
#include "wire/internal/crc32_copy.hpp"
#include "wire/internal/frame_checks.hpp"

namespace rsg::wire {

std::span<const std::uint8_t> FrameView::field_bytes(Field field) const {
  if (!contains(field)) return {};
  const FieldInfo& row = info(field);
  return bytes_.subspan(group_offsets_[row.group] + internal::offset_in_group(row, selection()),
                        row.wire_bytes);
}

DecodeResult decode(std::span<const std::uint8_t> bytes) noexcept {
  return internal::FrameDecoder::decode(
      bytes, [](std::span<const std::uint8_t> covered, const Selection*) { return crc32(covered); });
}

void copy_fields(const FrameView& frame, void* base, const FieldLayout& layout) noexcept {
  const detail::CopyPlan plan(frame.selection(), layout);
  internal::copy_to_struct(frame.bytes(), plan, static_cast<std::byte*>(base));
  internal::zero_fills(plan, base);
}

// Two passes (copy, then CRC) with a plan built for the call: for tools and tests, and the
// reference FrameCodec's stitched encoder is tested against.
EncodeResult encode(std::uint8_t packet_number, const Selection& selection, const void* base,
                    const FieldLayout& layout, std::span<std::uint8_t> out) noexcept {
  EncodeResult result;
  const std::size_t covered =
      internal::begin_encode(packet_number, selection, base, layout, out, result.error);
  if (covered == 0) return result;
  internal::copy_to_frame(out, detail::CopyPlan(selection, layout), static_cast<const std::byte*>(base));
  result.size = internal::finish_encode(out, covered, crc32(out.first(covered)));
  return result;
}

EncodeResult encode_selection_request(std::uint8_t packet_number, const Selection& selection,
                                      std::span<std::uint8_t> out) noexcept {
  EncodeResult result;
  if (!internal::check_encodable(packet_number, selection, kSelectionRequestBytes, out.size(), result.error))
    return result;
  internal::write_header(packet_number, selection, 0, out);
  internal::write_u32(out.data() + kHeaderBytes, crc32(out.first(kHeaderBytes)));
  result.size = kSelectionRequestBytes;
  return result;
}

SelectionRequestResult decode_selection_request(std::span<const std::uint8_t> bytes) noexcept {
  SelectionRequestResult result;
  if (bytes.size() < kSelectionRequestBytes) {
    result.error = {ErrorCategory::kTruncated, "%zu bytes, a selection request has %zu", bytes.size(),
                    kSelectionRequestBytes};
    return result;
  }
  const std::uint16_t length = internal::read_u16(bytes.data() + 1);
  if (length != 0 || bytes.size() != kSelectionRequestBytes) {
    result.error = {ErrorCategory::kLengthMismatch, "a selection request has length 0 and %zu bytes",
                    kSelectionRequestBytes};
    return result;
  }
  const std::uint32_t computed = crc32(bytes.first(kHeaderBytes));
  const std::uint32_t trailer = internal::read_u32(bytes.data() + kHeaderBytes);
  if (computed != trailer) {
    result.error = {ErrorCategory::kBadCrc, "trailer CRC is 0x%08x, computed 0x%08x", trailer, computed};
    return result;
  }
  internal::read_selection(bytes, result.selection);
  result.packet_number = bytes[0] & 0x0F;
  internal::check_header(bytes[0], result.selection, result.error);
  return result;
}

}  // namespace rsg::wire
