#include "tests/bench/e2e/stamped_frames.hpp"

#include <bit>
#include <cstring>
#include <stdexcept>

#include "rsg/dds/robot_state.hpp"

namespace rsg::bench {
namespace {

constexpr wire::Field kStampField = wire::Field::elbow_d;
static_assert(wire::info(kStampField).type == wire::ElementType::kFloat64 &&
              wire::info(kStampField).count == 2);
// Field bytes are little-endian doubles; reading them in place assumes the host agrees.
static_assert(std::endian::native == std::endian::little);

constexpr std::uint64_t kRobotModeMove = 2;

Stamp stamp_of(double index, double sent_ns) {
  return {static_cast<std::uint64_t>(index), static_cast<std::int64_t>(sent_ns)};
}

}  // namespace

StampedFrames::StampedFrames() {
  values_.selection = wire::Selection::all();
  // Distinct, finite values per field and element: any double will do, the codec does not care.
  for (const wire::FieldInfo& field : wire::kFields) {
    if (field.type != wire::ElementType::kFloat64) continue;
    std::span<double> elements = values_.doubles(field.id());
    for (std::size_t i = 0; i < elements.size(); ++i)
      elements[i] = field.index + 0.001 * static_cast<double>(i);
  }
  values_.set_integer(wire::Field::robot_mode, kRobotModeMove);
}

void StampedFrames::stamp_now(std::uint64_t index) {
  values_.packet_number = static_cast<std::uint8_t>(index % wire::kPacketNumberModulo);
  values_.set_integer(wire::Field::time, index);
  std::span<double> stamp = values_.doubles(kStampField);
  stamp[0] = static_cast<double>(index);
  stamp[1] = static_cast<double>(monotonic_ns());
}

std::span<const std::uint8_t> StampedFrames::encode() {
  const wire::EncodeResult encoded = rsg::wire::encode(
      values_.packet_number, values_.selection, values_.storage(), wire::StateValues::layout(), frame_);
  if (!encoded) throw std::logic_error("the bench's own frame does not encode");
  return std::span(frame_).first(encoded.size);
}

void StampedFrames::fill(RobotState& sample) const { dds::to_sample(values_, sample); }

std::optional<Stamp> read_stamp(const wire::FrameView& frame) {
  const std::span<const std::uint8_t> bytes = frame.field_bytes(kStampField);
  if (bytes.size() != 2 * sizeof(double)) return std::nullopt;
  std::array<double, 2> stamp{};
  std::memcpy(stamp.data(), bytes.data(), bytes.size());
  return stamp_of(stamp[0], stamp[1]);
}

Stamp read_stamp(const RobotState& sample) { return stamp_of(sample.elbow_d()[0], sample.elbow_d()[1]); }

}  // namespace rsg::bench
