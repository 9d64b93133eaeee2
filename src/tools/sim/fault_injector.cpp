#include "tools/sim/fault_injector.hpp"

#include <cassert>
#include <cstring>

#include "rsg/wire/crc32.hpp"

namespace rsg::tools::sim {
namespace {

constexpr std::size_t kLengthOffset = 1;
constexpr std::size_t kGroupSelectOffset = 3;
constexpr std::size_t kDataSelectOffset = 4;
constexpr std::uint8_t kPacketStartBit = 0x80;
constexpr std::uint8_t kReservedGroupBits[] = {0x40, 0x80};
constexpr std::uint8_t kReservedDataSelectBits[] = {0x10, 0x20, 0x40, 0x80};  // data_select[5] UNDEF1..4

bool chance(std::mt19937_64& random) { return random() & 1U; }

template <class T, std::size_t N>
T pick(std::mt19937_64& random, const T (&choices)[N]) {
  return choices[random() % N];
}

std::size_t encode_with(const wire::StateValues& values, const wire::Selection& selection,
                        std::span<std::uint8_t> out) {
  const wire::EncodeResult encoded =
      encode(values.packet_number, selection, values.storage(), wire::StateValues::layout(), out);
  assert(encoded && "the model only produces encodable values");
  return encoded.size;
}

void write_length(std::span<std::uint8_t> frame, std::size_t length) {
  frame[kLengthOffset] = static_cast<std::uint8_t>(length & 0xFF);
  frame[kLengthOffset + 1] = static_cast<std::uint8_t>(length >> 8);
}

// Recomputes the trailer after an edit, so that the frame gets past the CRC check to the one we aim at.
void reseal(std::span<std::uint8_t> frame) {
  const std::uint32_t crc = wire::crc32(frame.first(frame.size() - wire::kCrcBytes));
  std::memcpy(frame.data() + frame.size() - wire::kCrcBytes, &crc, sizeof crc);
}

// The wire bytes of `field` inside the valid frame `frame`.
std::span<std::uint8_t> field_bytes(std::span<std::uint8_t> frame, wire::Field field) {
  const wire::DecodeResult decoded = wire::decode(frame);
  assert(decoded && decoded.frame().contains(field));
  const std::span<const std::uint8_t> found = decoded.frame().field_bytes(field);
  return frame.subspan(static_cast<std::size_t>(found.data() - frame.data()), found.size());
}

// Step 2 (more bytes than the length field says) or step 7 (a length field that disagrees with
// data_select, with the bytes and CRC to match it).
std::size_t break_length(const wire::StateValues& values, std::mt19937_64& random,
                         std::span<std::uint8_t> out) {
  const std::size_t size = encode_with(values, values.selection, out);
  const std::size_t extra = 1 + random() % 8;
  if (chance(random)) {
    for (std::size_t i = 0; i < extra; ++i) out[size + i] = static_cast<std::uint8_t>(random());
    return size + extra;
  }
  const std::size_t data_bytes = size - wire::kMinFrameBytes + extra;
  std::memset(out.data() + size - wire::kCrcBytes, 0, extra);
  write_length(out, data_bytes);
  reseal(out.first(size + extra));
  return size + extra;
}

// Step 3: any single flipped bit outside the length field (which would be caught earlier).
std::size_t break_crc(const wire::StateValues& values, std::mt19937_64& random, std::span<std::uint8_t> out) {
  const std::size_t size = encode_with(values, values.selection, out);
  std::size_t byte = random() % (size - 2);
  if (byte >= kLengthOffset) byte += 2;
  out[byte] ^= static_cast<std::uint8_t>(1U << (random() % 8));
  return size;
}

// Step 4: PKT_START set, or a request type other than 3.
std::size_t break_request(const wire::StateValues& values, std::mt19937_64& random,
                          std::span<std::uint8_t> out) {
  const std::size_t size = encode_with(values, values.selection, out);
  if (chance(random)) {
    out[0] |= kPacketStartBit;
  } else {
    const std::uint8_t type = static_cast<std::uint8_t>((wire::kRequestType + 1 + random() % 7) % 8);
    out[0] = static_cast<std::uint8_t>((out[0] & 0x8F) | type << 4);
  }
  reseal(out.first(size));
  return size;
}

// Step 5 (GROUP6/GROUP7 or an UNDEF bit) or step 8 (error flags 37..39 in an error set).
std::size_t break_reserved(const wire::StateValues& values, std::mt19937_64& random,
                           std::span<std::uint8_t> out) {
  switch (random() % 3) {
    case 0: {
      const std::size_t size = encode_with(values, values.selection, out);
      out[kGroupSelectOffset] |= pick(random, kReservedGroupBits);
      reseal(out.first(size));
      return size;
    }
    case 1: {
      const std::size_t size = encode_with(values, values.selection, out);
      out[kDataSelectOffset + 5] |= pick(random, kReservedDataSelectBits);
      reseal(out.first(size));
      return size;
    }
    default: {
      const wire::Field error_set =
          chance(random) ? wire::Field::current_errors : wire::Field::last_motion_errors;
      wire::Selection selection = values.selection;
      selection.add(error_set);
      const std::size_t size = encode_with(values, selection, out);
      // Flags 37..39 are bits 5..7 of the set's fifth byte.
      field_bytes(out.first(size), error_set)[4] |= static_cast<std::uint8_t>(0x20U << (random() % 3));
      reseal(out.first(size));
      return size;
    }
  }
}

// Step 6: data_select bits in a group whose group_select bit is clear.
std::size_t break_selection(const wire::StateValues& values, std::mt19937_64& random,
                            std::span<std::uint8_t> out) {
  const std::size_t size = encode_with(values, values.selection, out);
  std::size_t group = random() % wire::kGroupCount;
  for (std::size_t g = 0; g < wire::kGroupCount; ++g)
    if (values.selection.data_select[g] != 0) group = g;
  out[kGroupSelectOffset] &= static_cast<std::uint8_t>(~(1U << group));
  out[kDataSelectOffset + group] |= 0x01;  // bit 0 is a field in every group, never a reserved bit
  reseal(out.first(size));
  return size;
}

// Step 8: a robot_mode outside 0..6, adding the field when the selection lacks it.
std::size_t break_value(const wire::StateValues& values, std::mt19937_64& random,
                        std::span<std::uint8_t> out) {
  wire::Selection selection = values.selection;
  selection.add(wire::Field::robot_mode);
  const std::size_t size = encode_with(values, selection, out);
  field_bytes(out.first(size), wire::Field::robot_mode)[0] = static_cast<std::uint8_t>(7 + random() % 249);
  reseal(out.first(size));
  return size;
}

}  // namespace

std::vector<wire::ErrorCategory> all_error_categories() {
  std::vector<wire::ErrorCategory> categories;
  for (std::size_t i = 1; i <= wire::kErrorCategoryCount; ++i)
    categories.push_back(static_cast<wire::ErrorCategory>(i));
  return categories;
}

FaultPlan::FaultPlan(FaultConfig config, std::uint64_t seed) : config_(std::move(config)), random_(seed) {
  if (config_.corrupt_categories.empty()) config_.corrupt_categories = all_error_categories();
}

Fault FaultPlan::next(std::uint64_t frame) {
  const auto every = [frame](std::uint64_t period) { return period != 0 && (frame + 1) % period == 0; };
  if (every(config_.drop_every)) return Fault::kDrop;
  if (every(config_.corrupt_every)) return Fault::kCorrupt;
  if (every(config_.duplicate_every)) return Fault::kDuplicate;
  if (every(config_.reorder_every)) return Fault::kReorder;

  // One draw per frame keeps the sequence of faults independent of which ones are enabled.
  double draw = std::uniform_real_distribution<double>(0, 1)(random_);
  for (const auto& [probability, fault] :
       {std::pair{config_.drop, Fault::kDrop}, std::pair{config_.corrupt, Fault::kCorrupt},
        std::pair{config_.duplicate, Fault::kDuplicate}, std::pair{config_.reorder, Fault::kReorder}}) {
    if (draw < probability) return fault;
    draw -= probability;
  }
  return Fault::kNone;
}

wire::ErrorCategory FaultPlan::next_category() {
  const wire::ErrorCategory category = config_.corrupt_categories[next_category_];
  next_category_ = (next_category_ + 1) % config_.corrupt_categories.size();
  return category;
}

std::size_t craft_invalid(wire::ErrorCategory category, const wire::StateValues& values,
                          std::mt19937_64& random, std::span<std::uint8_t> out) {
  assert(out.size() >= kCraftedDatagramBytes);
  switch (category) {
    case wire::ErrorCategory::kTruncated:
      // Any proper prefix: shorter than 14 bytes, or shorter than its length field says.
      return random() % encode_with(values, values.selection, out);
    case wire::ErrorCategory::kLengthMismatch:
      return break_length(values, random, out);
    case wire::ErrorCategory::kBadCrc:
      return break_crc(values, random, out);
    case wire::ErrorCategory::kBadRequest:
      return break_request(values, random, out);
    case wire::ErrorCategory::kReservedBits:
      return break_reserved(values, random, out);
    case wire::ErrorCategory::kSelectionMismatch:
      return break_selection(values, random, out);
    case wire::ErrorCategory::kBadValue:
      return break_value(values, random, out);
    case wire::ErrorCategory::kNone:
      break;
  }
  return encode_with(values, values.selection, out);
}

}  // namespace rsg::tools::sim
