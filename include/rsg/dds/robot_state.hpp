// Frames <-> the IDL `rsg::RobotState` sample, driven by the field table.
#pragma once

#include <RobotState.h>

#include <cstdint>
#include <span>

#include "rsg/wire/field_layout.hpp"
#include "rsg/wire/frame.hpp"
#include "rsg/wire/frame_codec.hpp"
#include "rsg/wire/state_values.hpp"

namespace rsg::dds {

/// Where each field lives inside the generated `RobotState` class.
const wire::FieldLayout& robot_state_layout();

/// Fills `sample` from a valid frame: header, `group_present`, every field (absent ones zeroed).
/// The field copy is the only copy of the payload on the way to DDS.
void to_sample(const wire::FrameView& frame, RobotState& sample) noexcept;
void to_sample(const wire::StateValues& values, RobotState& sample) noexcept;
void to_values(const RobotState& sample, wire::StateValues& values) noexcept;

/// Writes the frame the sample came from, byte for byte. Fails like `encode` when the sample could
/// not have come from a valid frame (e.g. written by a third-party app with robot_mode 9).
wire::EncodeResult to_frame(const RobotState& sample, std::span<std::uint8_t> out) noexcept;

/// The selection a sample carries.
wire::Selection selection_of(const RobotState& sample) noexcept;

/// Frames <-> samples for one stream of frames, the way the gateway does it: the payload is
/// copied in the same pass that checks the CRC (`FrameCodec`). Not thread-safe: one per stream.
class RobotStateCodec {
 public:
  RobotStateCodec() noexcept : codec_(dds::robot_state_layout()) {}

  /// Validates `frame` and fills `sample` like `to_sample`. On failure `sample` holds garbage
  /// (part of the rejected frame): never publish it.
  wire::DecodeResult decode(std::span<const std::uint8_t> frame, RobotState& sample) noexcept;
  /// `to_frame`.
  wire::EncodeResult encode(const RobotState& sample, std::span<std::uint8_t> out) noexcept;

 private:
  wire::FrameCodec codec_;
};

}  // namespace rsg::dds
