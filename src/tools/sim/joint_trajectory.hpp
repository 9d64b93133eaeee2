// Smooth, seeded joint motion for the simulated Panda.
#pragma once

#include <array>
#include <cstdint>

#include "tools/sim/panda.hpp"

namespace rsg::tools::sim {

/// Position, velocity and acceleration of every joint at one instant.
struct JointState {
  panda::Vector7d position;
  panda::Vector7d velocity;
  panda::Vector7d acceleration;
  panda::Vector7d jerk;  ///< for torque rates: the inertial torque changes with it
};

/// Each joint moves as a sum of a few sines around the ready pose. Sines make the derivatives exact
/// (no integration drift) and the motion repeatable from the seed alone; amplitudes are sized so that
/// position, velocity and acceleration stay strictly inside the Panda's limits for every t.
class JointTrajectory {
 public:
  static constexpr std::size_t kHarmonics = 3;

  explicit JointTrajectory(std::uint64_t seed);

  /// The motion at `t` seconds since the robot started.
  JointState at(double t) const;

 private:
  struct Harmonic {
    panda::Vector7d amplitude;  // rad
    panda::Vector7d omega;      // rad/s
    panda::Vector7d phase;      // rad
  };
  std::array<Harmonic, kHarmonics> harmonics_;
};

}  // namespace rsg::tools::sim
