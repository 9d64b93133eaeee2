// A DDS-free container for one frame's worth of field values, used by tools, JSON and tests.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "rsg/wire/field_layout.hpp"
#include "rsg/wire/field_table.hpp"
#include "rsg/wire/selection.hpp"

namespace rsg::wire {

class FrameView;

class StateValues {
 public:
  std::uint8_t packet_number = 0;
  Selection selection;

  /// Elements of a float64 field.
  std::span<double> doubles(Field field);
  std::span<const double> doubles(Field field) const;
  /// Value of an integer field: an error set (bit i = flag i), `robot_mode` or `time`.
  std::uint64_t integer(Field field) const;
  void set_integer(Field field, std::uint64_t value);

  /// Takes header and fields from a decoded frame.
  void assign(const FrameView& frame);

  static const FieldLayout& layout();
  void* storage() { return storage_.data(); }
  const void* storage() const { return storage_.data(); }
  static constexpr std::size_t storage_size() { return kStorageBytes; }

  friend bool operator==(const StateValues& a, const StateValues& b) {
    return a.packet_number == b.packet_number && a.selection == b.selection &&
           std::memcmp(a.storage_.data(), b.storage_.data(), a.storage_.size()) == 0;
  }

 private:
  static constexpr std::size_t kStorageBytes = [] {
    std::size_t total = 0;
    for (const FieldInfo& field : kFields) total += field.value_bytes();
    return total;
  }();
  alignas(8) std::array<std::byte, kStorageBytes> storage_{};
};

}  // namespace rsg::wire
