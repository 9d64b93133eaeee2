// The simulated robot's state: every field of the table, physically consistent with one motion.
#pragma once

#include <chrono>
#include <cstdint>

#include "rsg/wire/state_values.hpp"
#include "tools/sim/joint_trajectory.hpp"

namespace rsg::tools::sim {

/// Turns the joint trajectory into a full robot state. Measured values follow the desired ones one
/// control cycle behind, as a well-tuned joint impedance controller would; there is no contact, no
/// error, and the robot is in mode `move`. Pure function of time: no sockets, no clock.
class PandaModel {
 public:
  /// How far the desired trajectory (`q_d`, `dq_d`, `ddq_d`, `*_d`, `*_c`) runs ahead of the measured.
  static constexpr double kDesiredLeadSeconds = 0.001;

  explicit PandaModel(std::uint64_t seed) : trajectory_(seed) {}

  /// Writes the state `since_start` after the robot started into every field of `out` that `wanted`
  /// selects (others are left as they are); `time` is the whole milliseconds. Does not touch the header.
  void fill(std::chrono::nanoseconds since_start, const wire::Selection& wanted,
            wire::StateValues& out) const;

  const JointTrajectory& trajectory() const { return trajectory_; }

 private:
  JointTrajectory trajectory_;
};

}  // namespace rsg::tools::sim
