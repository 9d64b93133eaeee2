#include "rsg/frame.hpp"

#include <bit>
#include <cstring>

#include "rsg/crc32.hpp"
#include "rsg/error_flags.hpp"

namespace rsg {

static_assert(std::endian::native == std::endian::little,
              "fields are copied as raw little-endian bytes; a big-endian host needs byte swaps");

namespace {

constexpr std::uint8_t kPacketStartBit = 0x80;
constexpr std::uint8_t kReservedGroupBits = 0xC0;
constexpr std::uint8_t kReservedDataSelectBits = 0xF0;  // UNDEF1..UNDEF4 of data_select[5]

std::uint16_t read_u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | p[1] << 8); }

std::uint32_t read_u32(const std::uint8_t* p) {
  std::uint32_t value;
  std::memcpy(&value, p, sizeof value);
  return value;
}

void write_u32(std::uint8_t* p, std::uint32_t value) { std::memcpy(p, &value, sizeof value); }

std::uint64_t read_error_set(const std::uint8_t* p) {
  std::uint64_t value = 0;
  std::memcpy(&value, p, 5);
  return value;
}

// Checks 4..6 of the spec: the request byte, reserved selection bits, data without its group.
FrameError check_header(std::uint8_t request, const Selection& selection) {
  if (request & kPacketStartBit) return {ErrorCategory::kBadRequest, "PKT_START bit (0x80) of byte 0 is set"};
  if (((request >> 4) & 0x07) != kRequestType)
    return {ErrorCategory::kBadRequest, "request type is %u, expected 3", (request >> 4) & 0x07};
  if (selection.group_select & kReservedGroupBits)
    return {ErrorCategory::kReservedBits, "group_select 0x%02x sets reserved GROUP6/GROUP7",
            selection.group_select};
  if (selection.data_select[5] & kReservedDataSelectBits)
    return {ErrorCategory::kReservedBits, "data_select[5] 0x%02x sets reserved UNDEF bits",
            selection.data_select[5]};
  for (std::size_t group = 0; group < kGroupCount; ++group)
    if (selection.data_select[group] != 0 && !selection.has_group(group))
      return {ErrorCategory::kSelectionMismatch, "data_select[%zu] is 0x%02x but group %zu is not selected",
              group, selection.data_select[group], group};
  return {};
}

// Check 8 of the spec, for one field's wire bytes.
FrameError check_value(const FieldInfo& field, const std::uint8_t* wire) {
  if (field.type == ElementType::kErrorSet && (read_error_set(wire) & kReservedErrorBits))
    return {ErrorCategory::kReservedBits, "%s sets reserved error bits 37..39", field.name.data()};
  if (field.type == ElementType::kUInt8 && *wire > kMaxRobotMode)
    return {ErrorCategory::kBadValue, "%s is %u, valid modes are 0..6", field.name.data(), *wire};
  return {};
}

Selection read_selection(std::span<const std::uint8_t> bytes) {
  Selection selection;
  selection.group_select = bytes[3];
  std::memcpy(selection.data_select.data(), bytes.data() + 4, kGroupCount);
  return selection;
}

std::size_t write_header(std::uint8_t packet_number, const Selection& selection, std::uint16_t length,
                         std::span<std::uint8_t> out) {
  out[0] = static_cast<std::uint8_t>(kRequestType << 4 | packet_number);
  out[1] = static_cast<std::uint8_t>(length & 0xFF);
  out[2] = static_cast<std::uint8_t>(length >> 8);
  out[3] = selection.group_select;
  std::memcpy(out.data() + 4, selection.data_select.data(), kGroupCount);
  return kHeaderBytes;
}

FrameError check_encodable(std::uint8_t packet_number, const Selection& selection, std::size_t needed,
                           std::size_t available) {
  if (packet_number >= kPacketNumberModulo)
    return {ErrorCategory::kBadRequest, "packet number %u does not fit in 4 bits", packet_number};
  if (FrameError error = check_header(kRequestType << 4, selection)) return error;
  if (available < needed)
    return {ErrorCategory::kTruncated, "output buffer has %zu bytes, frame needs %zu", available, needed};
  return {};
}

}  // namespace

std::span<const std::uint8_t> FrameView::field_bytes(Field field) const {
  if (!contains(field)) return {};
  return bytes_.subspan(offsets_[static_cast<std::size_t>(field)], info(field).wire_bytes);
}

DecodeResult decode(std::span<const std::uint8_t> bytes) noexcept {
  DecodeResult result;
  FrameError& error = result.error_;
  if (bytes.size() < kMinFrameBytes) {
    error = {ErrorCategory::kTruncated, "%zu bytes, a frame has at least %zu", bytes.size(), kMinFrameBytes};
    return result;
  }
  const std::uint16_t length = read_u16(bytes.data() + 1);
  const std::size_t expected = kMinFrameBytes + length;
  if (bytes.size() != expected) {
    error = {bytes.size() < expected ? ErrorCategory::kTruncated : ErrorCategory::kLengthMismatch,
             "%zu bytes, the length field (%u) implies %zu", bytes.size(), length, expected};
    return result;
  }
  const std::uint32_t computed = crc32(bytes.first(kHeaderBytes + length));
  const std::uint32_t trailer = read_u32(bytes.data() + kHeaderBytes + length);
  if (computed != trailer) {
    error = {ErrorCategory::kBadCrc, "trailer CRC is 0x%08x, computed 0x%08x", trailer, computed};
    return result;
  }
  FrameView& frame = result.frame_;
  frame.bytes_ = bytes;
  frame.header_.packet_number = bytes[0] & 0x0F;
  frame.header_.selection = read_selection(bytes);
  frame.header_.length = length;
  if ((error = check_header(bytes[0], frame.header_.selection))) return result;

  std::uint16_t offset = kHeaderBytes;
  for (const FieldInfo& field : kFields) {
    if (!(bytes[4 + field.group] & field.mask)) continue;
    frame.offsets_[field.index] = offset;
    offset = static_cast<std::uint16_t>(offset + field.wire_bytes);
  }
  if (offset - kHeaderBytes != length) {
    error = {ErrorCategory::kLengthMismatch, "length field says %u data bytes, data_select implies %zu",
             length, offset - kHeaderBytes};
    return result;
  }
  for (const FieldInfo& field : kFields) {
    if (field.type == ElementType::kFloat64 || !frame.contains(field.id())) continue;
    if ((error = check_value(field, bytes.data() + frame.offsets_[field.index]))) return result;
  }
  return result;
}

void copy_fields(const FrameView& frame, void* base, const FieldLayout& layout) noexcept {
  const std::uint8_t* wire = frame.bytes().data() + kHeaderBytes;
  for (const FieldInfo& field : kFields) {
    std::byte* value = layout.locate(base, field.id());
    if (!frame.contains(field.id())) {
      std::memset(value, 0, field.value_bytes());
      continue;
    }
    if (field.type == ElementType::kErrorSet) {
      const std::uint64_t bits = read_error_set(wire);
      std::memcpy(value, &bits, sizeof bits);
    } else {
      std::memcpy(value, wire, field.wire_bytes);
    }
    wire += field.wire_bytes;
  }
}

EncodeResult encode(std::uint8_t packet_number, const Selection& selection, const void* base,
                    const FieldLayout& layout, std::span<std::uint8_t> out) noexcept {
  EncodeResult result;
  const std::uint16_t length = selection.data_bytes();
  const std::size_t size = kMinFrameBytes + length;
  if ((result.error = check_encodable(packet_number, selection, size, out.size()))) return result;

  std::uint8_t* wire = out.data() + write_header(packet_number, selection, length, out);
  for (const FieldInfo& field : kFields) {
    if (!selection.contains(field.id())) continue;
    const std::byte* value = layout.locate(base, field.id());
    if (field.type == ElementType::kErrorSet) {
      std::uint64_t bits;
      std::memcpy(&bits, value, sizeof bits);
      if (bits >> kErrorFlagCount) {
        result.error = {ErrorCategory::kReservedBits, "%s has bits above flag 36 set", field.name.data()};
        return result;
      }
    }
    std::memcpy(wire, value, field.wire_bytes);  // an error set's low 5 bytes are its wire form
    if ((result.error = check_value(field, wire))) return result;
    wire += field.wire_bytes;
  }
  write_u32(wire, crc32(out.first(kHeaderBytes + length)));
  result.size = size;
  return result;
}

EncodeResult encode_selection_request(std::uint8_t packet_number, const Selection& selection,
                                      std::span<std::uint8_t> out) noexcept {
  EncodeResult result;
  if ((result.error = check_encodable(packet_number, selection, kSelectionRequestBytes, out.size())))
    return result;
  write_header(packet_number, selection, 0, out);
  write_u32(out.data() + kHeaderBytes, crc32(out.first(kHeaderBytes)));
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
  const std::uint16_t length = read_u16(bytes.data() + 1);
  if (length != 0 || bytes.size() != kSelectionRequestBytes) {
    result.error = {ErrorCategory::kLengthMismatch, "a selection request has length 0 and %zu bytes",
                    kSelectionRequestBytes};
    return result;
  }
  const std::uint32_t computed = crc32(bytes.first(kHeaderBytes));
  const std::uint32_t trailer = read_u32(bytes.data() + kHeaderBytes);
  if (computed != trailer) {
    result.error = {ErrorCategory::kBadCrc, "trailer CRC is 0x%08x, computed 0x%08x", trailer, computed};
    return result;
  }
  result.selection = read_selection(bytes);
  result.packet_number = bytes[0] & 0x0F;
  result.error = check_header(bytes[0], result.selection);
  return result;
}

}  // namespace rsg
