#include "rsg/dds/robot_state.hpp"

#include <cstring>
#include <type_traits>

namespace rsg::dds {
namespace {

// The field table names the IDL members, so the offsets come from the generated accessors.
// A field whose IDL shape differs from the table fails to compile here.
wire::FieldLayout make_robot_state_layout() {
  wire::FieldLayout layout;
  RobotState probe;  // non-const: scalar accessors return references only then
  const auto* base = reinterpret_cast<const std::byte*>(&probe);
#define RSG_LOCATE_MEMBER(name, index, group, mask, type, count, bytes)                                    \
  static_assert(sizeof(std::remove_cvref_t<decltype(probe.name())>) == wire::kFields[index].value_bytes(), \
                "IDL member " #name " does not match the field table");                                    \
  layout.offsets[index] =                                                                                  \
      static_cast<std::uint32_t>(reinterpret_cast<const std::byte*>(&probe.name()) - base);
  RSG_FIELDS(RSG_LOCATE_MEMBER)
#undef RSG_LOCATE_MEMBER
  return layout;
}

void set_header(std::uint8_t packet_number, const wire::Selection& selection, RobotState& sample) {
  sample.packet_number(packet_number);
  sample.group_select(selection.group_select);
  std::memcpy(sample.data_select().data(), selection.data_select.data(), wire::kGroupCount);
  for (std::size_t group = 0; group < wire::kGroupCount; ++group)
    sample.group_present()[group] = selection.has_group(group);
}

void copy_values(const void* from, const wire::FieldLayout& from_layout, void* to,
                 const wire::FieldLayout& to_layout) {
  for (const wire::FieldInfo& field : wire::kFields)
    std::memcpy(to_layout.locate(to, field.id()), from_layout.locate(from, field.id()), field.value_bytes());
}

}  // namespace

const wire::FieldLayout& robot_state_layout() {
  static const wire::FieldLayout layout = make_robot_state_layout();
  return layout;
}

wire::Selection selection_of(const RobotState& sample) noexcept {
  wire::Selection selection;
  selection.group_select = sample.group_select();
  std::memcpy(selection.data_select.data(), sample.data_select().data(), wire::kGroupCount);
  return selection;
}

void to_sample(const wire::FrameView& frame, RobotState& sample) noexcept {
  set_header(frame.packet_number(), frame.selection(), sample);
  wire::copy_fields(frame, &sample, dds::robot_state_layout());
}

void to_sample(const wire::StateValues& values, RobotState& sample) noexcept {
  set_header(values.packet_number, values.selection, sample);
  copy_values(values.storage(), wire::StateValues::layout(), &sample, dds::robot_state_layout());
}

void to_values(const RobotState& sample, wire::StateValues& values) noexcept {
  values.packet_number = sample.packet_number();
  values.selection = dds::selection_of(sample);
  copy_values(&sample, dds::robot_state_layout(), values.storage(), wire::StateValues::layout());
}

wire::EncodeResult to_frame(const RobotState& sample, std::span<std::uint8_t> out) noexcept {
  return encode(sample.packet_number(), selection_of(sample), &sample, robot_state_layout(), out);
}

wire::DecodeResult RobotStateCodec::decode(std::span<const std::uint8_t> frame, RobotState& sample) noexcept {
  wire::DecodeResult result = codec_.decode(frame, &sample);
  if (result) set_header(result.frame().packet_number(), result.frame().selection(), sample);
  return result;
}

wire::EncodeResult RobotStateCodec::encode(const RobotState& sample, std::span<std::uint8_t> out) noexcept {
  return codec_.encode(sample.packet_number(), selection_of(sample), &sample, out);
}

}  // namespace rsg::dds
