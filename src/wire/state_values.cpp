#include "rsg/wire/state_values.hpp"

#include <cassert>

#include "rsg/wire/frame.hpp"

namespace rsg::wire {

const FieldLayout& StateValues::layout() {
  static constexpr FieldLayout kLayout = [] {
    FieldLayout layout;
    std::uint32_t offset = 0;
    for (const FieldInfo& field : kFields) {
      layout.offsets[field.index] = offset;
      offset += field.value_bytes();
    }
    return layout;
  }();
  return kLayout;
}

std::span<double> StateValues::doubles(Field field) {
  assert(info(field).type == ElementType::kFloat64);
  return {reinterpret_cast<double*>(layout().locate(storage(), field)), info(field).count};
}

std::span<const double> StateValues::doubles(Field field) const {
  assert(info(field).type == ElementType::kFloat64);
  return {reinterpret_cast<const double*>(layout().locate(storage(), field)), info(field).count};
}

std::uint64_t StateValues::integer(Field field) const {
  const FieldInfo& row = info(field);
  assert(row.type != ElementType::kFloat64);
  std::uint64_t value = 0;
  std::memcpy(&value, layout().locate(storage(), field), row.value_bytes());
  return value;
}

void StateValues::set_integer(Field field, std::uint64_t value) {
  const FieldInfo& row = info(field);
  assert(row.type != ElementType::kFloat64);
  std::memcpy(layout().locate(storage(), field), &value, row.value_bytes());
}

void StateValues::assign(const FrameView& frame) {
  packet_number = frame.packet_number();
  selection = frame.selection();
  copy_fields(frame, storage(), layout());
}

}  // namespace rsg::wire
