// What decoding and encoding share, for the free functions (frame.cpp) and FrameCodec
// (frame_codec.cpp): the spec's checks, the header's reads and writes, and the decoder. Internal to
// rsg_wire; everything is inline so that each of the two keeps the per-frame path free of calls.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <span>
#include <utility>

#include "rsg/wire/detail/copy_plan.hpp"
#include "rsg/wire/error_flags.hpp"
#include "rsg/wire/frame.hpp"
#include "wire/internal/group_bytes.hpp"

namespace rsg::wire::internal {

static_assert(std::endian::native == std::endian::little,
              "fields are copied as raw little-endian bytes; a big-endian host needs byte swaps");

constexpr std::uint8_t kPacketStartBit = 0x80;
constexpr std::uint8_t kReservedGroupBits = 0xC0;
constexpr std::uint8_t kReservedDataSelectBits = 0xF0;  // UNDEF1..UNDEF4 of data_select[5]

/// Types with a rule on their values (validation step 8). Any bit pattern of the others is valid.
constexpr bool has_value_rule(ElementType type) {
  return type == ElementType::kErrorSet || type == ElementType::kUInt8;
}

/// The rows of the field table whose values are checked, so that validation visits 3 fields, not 44.
constexpr auto kRuledFields = [] {
  constexpr auto ruled = [](const FieldInfo& field) { return has_value_rule(field.type); };
  std::array<FieldInfo, std::ranges::count_if(kFields, ruled)> fields{};
  std::ranges::copy_if(kFields, fields.begin(), ruled);
  return fields;
}();

inline std::uint16_t read_u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | p[1] << 8); }

inline std::uint32_t read_u32(const std::uint8_t* p) {
  std::uint32_t value;
  std::memcpy(&value, p, sizeof value);
  return value;
}

inline void write_u32(std::uint8_t* p, std::uint32_t value) { std::memcpy(p, &value, sizeof value); }

// Two loads rather than a 5-byte memcpy into a uint64: reading the uint64 back right after that
// partial store would stall on store-to-load forwarding.
inline std::uint64_t read_error_set(const void* p) {
  const auto* bytes = static_cast<const std::uint8_t*>(p);
  return read_u32(bytes) | std::uint64_t{bytes[4]} << 32;
}

// The six data_select bytes as one integer, byte g at bits 8g..8g+7, by a 4-byte and a 2-byte load:
// GCC compiles a 6-byte memcpy into a zeroed uint64 to stores into a stack slot and an 8-byte
// reload of it, which stalls on store-to-load forwarding every time (most of header_passes's
// samples in perf on an Intel Xeon: docs/benchmarks/wire.md).
inline std::uint64_t read_data_select(const Selection& selection) {
  static_assert(kGroupCount == 6, "a 4-byte and a 2-byte load");
  const std::uint8_t* bytes = selection.data_select.data();
  std::uint16_t high;
  std::memcpy(&high, bytes + 4, sizeof high);
  return read_u32(bytes) | std::uint64_t{high} << 32;
}

// The checks below fill `error` and return false at the first failure. They leave `error` alone on
// success: building a FrameError clears its message buffer, too much work for every valid frame.

// Checks 4..6 of the spec: the request byte, reserved selection bits, data without its group.
inline bool check_header(std::uint8_t request, const Selection& selection, FrameError& error) {
  if (request & kPacketStartBit) {
    error = {ErrorCategory::kBadRequest, "PKT_START bit (0x80) of byte 0 is set"};
    return false;
  }
  if (((request >> 4) & 0x07) != kRequestType) {
    error = {ErrorCategory::kBadRequest, "request type is %u, expected 3", (request >> 4) & 0x07};
    return false;
  }
  if (selection.group_select & kReservedGroupBits) {
    error = {ErrorCategory::kReservedBits, "group_select 0x%02x sets reserved GROUP6/GROUP7",
             selection.group_select};
    return false;
  }
  if (selection.data_select[5] & kReservedDataSelectBits) {
    error = {ErrorCategory::kReservedBits, "data_select[5] 0x%02x sets reserved UNDEF bits",
             selection.data_select[5]};
    return false;
  }
  for (std::size_t group = 0; group < kGroupCount; ++group) {
    if (selection.data_select[group] != 0 && !selection.has_group(group)) {
      error = {ErrorCategory::kSelectionMismatch, "data_select[%zu] is 0x%02x but group %zu is not selected",
               group, selection.data_select[group], group};
      return false;
    }
  }
  return true;
}

// Checks 4..6 when they pass, the common case, without branches: check_header's branches and
// error messages show in the codec's cost next to a fast CRC (docs/benchmarks/wire.md). check_header
// still runs when this says no, to name the first failure.
inline bool header_passes(std::uint8_t request, const Selection& selection) {
  constexpr std::uint64_t kLow7 = 0x7F7F'7F7F'7F7F;  // per data_select byte
  constexpr std::uint64_t kHigh = 0x8080'8080'8080;
  const std::uint64_t data = read_data_select(selection);
  // High bit of byte g: data_select[g] selects something / group g is selected. The product
  // moves bit g of group_select to bit 8g + 7; no two partial products share a bit, so no carries.
  const std::uint64_t carried = (((data & kLow7) + kLow7) | data) & kHigh;
  const std::uint64_t groups = (std::uint64_t{selection.group_select & 0x3FU} * 0x0408'1020'4080ULL) & kHigh;
  static_assert(kGroupCount == 6, "the masks and the product above have a byte per group");
  return (request & (kPacketStartBit | 0x70)) == kRequestType << 4 &&
         !(selection.group_select & kReservedGroupBits) &&
         !(selection.data_select[5] & kReservedDataSelectBits) && !(carried & ~groups);
}

// Check 8 of the spec on one field's bytes, which for these types are the same on the wire and in
// memory (an error set's first 5 bytes in memory are its wire form).
inline bool check_value(const FieldInfo& field, const void* bytes, FrameError& error) {
  if (field.type == ElementType::kErrorSet && (read_error_set(bytes) & kReservedErrorBits)) {
    error = {ErrorCategory::kReservedBits, "%s sets reserved error bits 37..39", field.name.data()};
    return false;
  }
  const std::uint8_t byte = *static_cast<const std::uint8_t*>(bytes);
  if (field.type == ElementType::kUInt8 && byte > kMaxRobotMode) {
    error = {ErrorCategory::kBadValue, "%s is %u, valid modes are 0..6", field.name.data(), byte};
    return false;
  }
  return true;
}

// Fills the selection in place: building a copy and moving it would reload freshly stored bytes at
// other widths and stall on store-to-load forwarding, a measurable part of decoding a frame.
inline void read_selection(std::span<const std::uint8_t> bytes, Selection& selection) {
  selection.group_select = bytes[3];
  std::memcpy(selection.data_select.data(), bytes.data() + 4, kGroupCount);
}

inline std::size_t write_header(std::uint8_t packet_number, const Selection& selection, std::uint16_t length,
                                std::span<std::uint8_t> out) {
  out[0] = static_cast<std::uint8_t>(kRequestType << 4 | packet_number);
  out[1] = static_cast<std::uint8_t>(length & 0xFF);
  out[2] = static_cast<std::uint8_t>(length >> 8);
  out[3] = selection.group_select;
  std::memcpy(out.data() + 4, selection.data_select.data(), kGroupCount);
  return kHeaderBytes;
}

inline bool check_encodable(std::uint8_t packet_number, const Selection& selection, std::size_t needed,
                            std::size_t available, FrameError& error) {
  if (packet_number >= kPacketNumberModulo) {
    error = {ErrorCategory::kBadRequest, "packet number %u does not fit in 4 bits", packet_number};
    return false;
  }
  if (!header_passes(kRequestType << 4, selection) && !check_header(kRequestType << 4, selection, error))
    return false;
  if (available < needed) {
    error = {ErrorCategory::kTruncated, "output buffer has %zu bytes, frame needs %zu", available, needed};
    return false;
  }
  return true;
}

/// Step 8 of the spec on a struct about to be encoded, which may have been filled by anyone.
inline bool check_values(const Selection& selection, const void* base, const FieldLayout& layout,
                         FrameError& error) {
  for (const FieldInfo& field : kRuledFields) {
    if (!selection.contains(field.id())) continue;
    const std::byte* value = layout.locate(base, field.id());
    if (field.type == ElementType::kErrorSet) {
      std::uint64_t bits;
      std::memcpy(&bits, value, sizeof bits);
      if (bits >> kErrorFlagCount) {  // a frame has room for flags 0..39 only
        error = {ErrorCategory::kReservedBits, "%s has bits above flag 36 set", field.name.data()};
        return false;
      }
    }
    if (!check_value(field, value, error)) return false;
  }
  return true;
}

/// A selection's 7 bytes as one integer, the way they sit in a header (bytes 3..9).
inline std::uint64_t selection_key(const Selection& selection) {
  return read_data_select(selection) << 8 | selection.group_select;
}

/// The same read from the frame's bytes rather than from the Selection just filled from them:
/// reloading freshly stored bytes at another width would stall on store-to-load forwarding. One
/// 8-byte load of bytes 2..9 (inside the header), shifted: a 7-byte memcpy into a zeroed integer
/// compiled to two 4-byte stores and an 8-byte reload, which stalls the same way
/// (docs/benchmarks/wire.md).
inline std::uint64_t selection_key(std::span<const std::uint8_t> frame) {
  static_assert(kHeaderBytes >= 3 + 1 + kGroupCount, "bytes 2..9 lie in the header");
  std::uint64_t bytes;
  std::memcpy(&bytes, frame.data() + 2, sizeof bytes);
  return bytes >> 8;
}

/// Checks what `encode` refuses and writes the header. Returns the bytes the CRC will cover, or 0
/// with `error` set.
inline std::size_t begin_encode(std::uint8_t packet_number, const Selection& selection, const void* base,
                                const FieldLayout& layout, std::span<std::uint8_t> out, FrameError& error) {
  const std::uint16_t length = selection.data_bytes();
  if (!check_encodable(packet_number, selection, kMinFrameBytes + length, out.size(), error)) return 0;
  if (!check_values(selection, base, layout, error)) return 0;
  return write_header(packet_number, selection, length, out) + length;
}

/// Writes the trailer after the `covered` bytes; returns the frame's size.
inline std::size_t finish_encode(std::span<std::uint8_t> out, std::size_t covered, std::uint32_t crc) {
  write_u32(out.data() + covered, crc);
  return covered + kCrcBytes;
}

/// Zeroes [p, p + size) for size 1..16 with two fixed-size stores that may overlap.
inline void zero_small(std::byte* p, std::size_t size) {
  const auto zero_fixed = [](std::byte* at, auto width) {
    const decltype(width) zero = 0;
    std::memcpy(at, &zero, sizeof zero);
  };
  if (size >= 8) {
    zero_fixed(p, std::uint64_t{});
    zero_fixed(p + size - 8, std::uint64_t{});
  } else if (size >= 4) {
    zero_fixed(p, std::uint32_t{});
    zero_fixed(p + size - 4, std::uint32_t{});
  } else {  // 1..3
    p[0] = p[size / 2] = p[size - 1] = std::byte{0};
  }
}

// A full frame leaves only the high bytes of its 5-byte error sets (3 bytes each): stored in place
// rather than through a memset call per fill.
inline void zero_fills(const detail::CopyPlan& plan, void* base) {
  for (const detail::ByteFill& fill : plan.fills()) {
    std::byte* at = static_cast<std::byte*>(base) + fill.begin;
    if (fill.size <= 16)
      zero_small(at, fill.size);
    else
      std::memset(at, 0, fill.size);
  }
}

/// The spec's validation, shared by `decode` and `FrameCodec::decode`, which copies the fields in
/// the CRC pass. The header is read before the CRC so that the copy knows where the fields are;
/// failures are still reported in the spec's order.
class FrameDecoder {
 public:
  /// `checksum(covered, selection)` returns the CRC-32 of the covered bytes. `selection` points to
  /// the frame's selection when the header is consistent with the frame's length (so a copy by it
  /// stays inside the frame), else it is null.
  template <class Checksum>
  static DecodeResult decode(std::span<const std::uint8_t> bytes, Checksum&& checksum) noexcept {
    DecodeResult result;
    FrameError& error = result.error_;
    if (bytes.size() < kMinFrameBytes) {
      error = {ErrorCategory::kTruncated, "%zu bytes, a frame has at least %zu", bytes.size(),
               kMinFrameBytes};
      return result;
    }
    // Longer than the longest frame: length_mismatch whatever the bytes say, so that a receiver
    // whose buffer holds one frame (the gateway's) and one that sees every byte agree.
    if (bytes.size() > kMaxFrameBytes) {
      error = {ErrorCategory::kLengthMismatch, "%zu bytes, longer than any frame (%zu)", bytes.size(),
               kMaxFrameBytes};
      return result;
    }
    const std::uint16_t length = read_u16(bytes.data() + 1);
    const std::size_t expected = kMinFrameBytes + length;
    if (bytes.size() != expected) {
      error = {bytes.size() < expected ? ErrorCategory::kTruncated : ErrorCategory::kLengthMismatch,
               "%zu bytes, the length field (%u) implies %zu", bytes.size(), length, expected};
      return result;
    }
    FrameView& frame = result.frame_;
    frame.bytes_ = bytes;
    frame.header_.packet_number = bytes[0] & 0x0F;
    read_selection(bytes, frame.header_.selection);
    frame.header_.length = length;
    const Selection& selection = frame.header_.selection;
    std::uint16_t offset = kHeaderBytes;
    for (std::size_t group = 0; group < kGroupCount; ++group) {
      frame.group_offsets_[group] = offset;
      offset = static_cast<std::uint16_t>(offset + kSelectedBytes[group][selection.data_select[group]]);
    }
    const std::size_t selected_bytes = offset - kHeaderBytes;

    // A header failure is kept in `error` and reported only once the CRC has passed.
    const bool header_valid = header_passes(bytes[0], selection) || check_header(bytes[0], selection, error);
    const std::uint32_t computed = checksum(bytes.first(kHeaderBytes + length),
                                            header_valid && selected_bytes == length ? &selection : nullptr);
    const std::uint32_t trailer = read_u32(bytes.data() + kHeaderBytes + length);
    if (computed != trailer) {
      error = {ErrorCategory::kBadCrc, "trailer CRC is 0x%08x, computed 0x%08x", trailer, computed};
      return result;
    }
    if (!header_valid) return result;
    if (selected_bytes != length) {
      error = {ErrorCategory::kLengthMismatch, "length field says %u data bytes, data_select implies %zu",
               length, selected_bytes};
      return result;
    }
    if (values_pass(frame, std::make_index_sequence<kRuledFields.size()>())) return result;
    for (const FieldInfo& field : kRuledFields)
      if (selection.contains(field.id()) && !check_value(field, frame.field_bytes(field.id()).data(), error))
        return result;
    return result;
  }

 private:
  /// Check 8 when it passes, the common case: unrolled over the ruled fields, so that each field's
  /// row is a constant and its offset two table loads, with no calls. The loop above names the
  /// failure otherwise.
  template <std::size_t... I>
  static bool values_pass(const FrameView& frame, std::index_sequence<I...>) {
    return (value_passes<I>(frame) && ...);
  }
  template <std::size_t I>
  static bool value_passes(const FrameView& frame) {
    constexpr const FieldInfo& field = kRuledFields[I];
    const Selection& selection = frame.header_.selection;
    if (!selection.contains(field.id())) return true;
    const std::uint8_t* bytes =
        frame.bytes_.data() + frame.group_offsets_[field.group] + offset_in_group(field, selection);
    if constexpr (field.type == ElementType::kErrorSet) return !(read_error_set(bytes) & kReservedErrorBits);
    return *bytes <= kMaxRobotMode;
  }
};

}  // namespace rsg::wire::internal
