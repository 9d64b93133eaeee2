#include "tools/sim/joint_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace rsg::tools::sim {
namespace {

using panda::Vector7d;

// A slow, visible motion: at most 0.6 rad either side of the ready pose, periods of 3 to 20 s, and
// never more than half of any limit, so that q_d (a little ahead of q) is inside the limits as well.
constexpr double kMaxSwing = 0.6;
constexpr double kLimitShare = 0.5;
constexpr double kMinFrequencyHz = 0.05;
constexpr double kMaxFrequencyHz = 0.35;

}  // namespace

JointTrajectory::JointTrajectory(std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> weight(0.2, 1.0);
  std::uniform_real_distribution<double> frequency(kMinFrequencyHz, kMaxFrequencyHz);
  std::uniform_real_distribution<double> phase(0, 2 * EIGEN_PI);

  Vector7d weight_sum = Vector7d::Zero();
  for (Harmonic& harmonic : harmonics_) {
    for (Eigen::Index joint = 0; joint < harmonic.amplitude.size(); ++joint) {
      harmonic.amplitude[joint] = weight(random);
      harmonic.omega[joint] = 2 * EIGEN_PI * frequency(random);
      harmonic.phase[joint] = phase(random);
    }
    weight_sum += harmonic.amplitude;
  }

  const auto centre = wire::eigen::joints(panda::kReadyPose);
  const auto position_min = wire::eigen::joints(panda::kPositionMin);
  const auto position_max = wire::eigen::joints(panda::kPositionMax);
  const Vector7d room = (centre - position_min).cwiseMin(position_max - centre);
  const Vector7d swing = (kLimitShare * room).cwiseMin(kMaxSwing);

  // Peaks of |position - centre|, |velocity| and |acceleration| are bounded by the sums of
  // A, A*omega and A*omega^2: scale each joint so that all three stay within their share.
  Vector7d velocity_peak = Vector7d::Zero();
  Vector7d acceleration_peak = Vector7d::Zero();
  for (Harmonic& harmonic : harmonics_) {
    harmonic.amplitude = harmonic.amplitude.cwiseQuotient(weight_sum).cwiseProduct(swing);
    velocity_peak += harmonic.amplitude.cwiseProduct(harmonic.omega);
    acceleration_peak += harmonic.amplitude.cwiseProduct(harmonic.omega).cwiseProduct(harmonic.omega);
  }
  const Vector7d velocity_scale =
      (kLimitShare * wire::eigen::joints(panda::kVelocityMax)).cwiseQuotient(velocity_peak);
  const Vector7d acceleration_scale =
      (kLimitShare * wire::eigen::joints(panda::kAccelerationMax)).cwiseQuotient(acceleration_peak);
  const Vector7d scale = velocity_scale.cwiseMin(acceleration_scale).cwiseMin(1.0);
  for (Harmonic& harmonic : harmonics_) harmonic.amplitude = harmonic.amplitude.cwiseProduct(scale);
}

JointState JointTrajectory::at(double t) const {
  JointState state{wire::eigen::joints(panda::kReadyPose), Vector7d::Zero(), Vector7d::Zero(),
                   Vector7d::Zero()};
  for (const Harmonic& harmonic : harmonics_) {
    for (Eigen::Index joint = 0; joint < harmonic.amplitude.size(); ++joint) {
      const double amplitude = harmonic.amplitude[joint];
      const double omega = harmonic.omega[joint];
      const double angle = omega * t + harmonic.phase[joint];
      const double sine = std::sin(angle);
      const double cosine = std::cos(angle);
      state.position[joint] += amplitude * sine;
      state.velocity[joint] += amplitude * omega * cosine;
      state.acceleration[joint] -= amplitude * omega * omega * sine;
      state.jerk[joint] -= amplitude * omega * omega * omega * cosine;
    }
  }
  return state;
}

}  // namespace rsg::tools::sim
