// Decoding and encoding SEND_BUF frames (docs/protocol.md). No allocation, no DDS.
//
//   auto result = rsg::wire::decode(bytes);
//   if (!result) { count(result.error().category()); return; }
//   rsg::wire::copy_fields(result.frame(), &sample, layout);
//
// A stream decoded into structs frame after frame is faster through `FrameCodec`
// (rsg/wire/frame_codec.hpp), which copies during the CRC pass.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "rsg/wire/error.hpp"
#include "rsg/wire/field_layout.hpp"
#include "rsg/wire/field_table.hpp"
#include "rsg/wire/selection.hpp"

namespace rsg::wire {

inline constexpr std::size_t kHeaderBytes = 10;
inline constexpr std::size_t kCrcBytes = 4;
inline constexpr std::size_t kMinFrameBytes = kHeaderBytes + kCrcBytes;
inline constexpr std::size_t kMaxFrameBytes = kMinFrameBytes + kMaxDataBytes;  // 2137
inline constexpr std::uint8_t kRequestType = 3;
inline constexpr std::uint8_t kPacketNumberModulo = 16;

struct FrameHeader {
  std::uint8_t packet_number = 0;
  Selection selection;
  std::uint16_t length = 0;  ///< bytes of the data section
};

class DecodeResult;
/// Validates a frame in the spec's order and reports the first failure.
DecodeResult decode(std::span<const std::uint8_t> bytes) noexcept;

namespace internal {
class FrameDecoder;  // the validation behind `decode` and `FrameCodec::decode`: never installed (src/wire/)
}

/// A frame that passed every check of the spec. Refers to the caller's bytes, which must outlive it.
class FrameView {
 public:
  const FrameHeader& header() const { return header_; }
  std::uint8_t packet_number() const { return header_.packet_number; }
  const Selection& selection() const { return header_.selection; }
  bool contains(Field field) const { return header_.selection.contains(field); }
  /// The field's bytes as they are on the wire; empty when the frame does not carry it.
  std::span<const std::uint8_t> field_bytes(Field field) const;
  std::span<const std::uint8_t> bytes() const { return bytes_; }

 private:
  friend class internal::FrameDecoder;

  std::span<const std::uint8_t> bytes_;
  FrameHeader header_;
  std::array<std::uint16_t, kGroupCount> group_offsets_{};  // into bytes_: where each group's data starts
};

/// Either a valid frame or the first check it failed.
class DecodeResult {
 public:
  explicit operator bool() const { return !error_; }
  const FrameView& frame() const { return frame_; }
  const FrameError& error() const { return error_; }

 private:
  friend class internal::FrameDecoder;
  FrameView frame_;
  FrameError error_;
};

/// Copies every field of `frame` into the struct at `base` (laid out as `layout` says) and zeroes
/// the fields the frame does not carry, so a reused sample never shows stale values.
void copy_fields(const FrameView& frame, void* base, const FieldLayout& layout) noexcept;

struct EncodeResult {
  std::size_t size = 0;  ///< bytes written, 0 on error
  FrameError error;
  explicit operator bool() const { return !error; }
};

/// Writes a frame carrying `selection`'s fields, read from the struct at `base`. Refuses (with the
/// category a decoder would report) anything that would not decode: reserved bits, a selection
/// that does not match its groups, packet numbers above 15, error flags 37..39, robot_mode > 6.
EncodeResult encode(std::uint8_t packet_number, const Selection& selection, const void* base,
                    const FieldLayout& layout, std::span<std::uint8_t> out) noexcept;

/// The spec's selection request (gateway -> robot): a header with length 0 and a CRC.
inline constexpr std::size_t kSelectionRequestBytes = kMinFrameBytes;
EncodeResult encode_selection_request(std::uint8_t packet_number, const Selection& selection,
                                      std::span<std::uint8_t> out) noexcept;

struct SelectionRequestResult {
  Selection selection;
  std::uint8_t packet_number = 0;
  FrameError error;
  explicit operator bool() const { return !error; }
};
/// Reads a selection request as a robot would.
SelectionRequestResult decode_selection_request(std::span<const std::uint8_t> bytes) noexcept;

}  // namespace rsg::wire
