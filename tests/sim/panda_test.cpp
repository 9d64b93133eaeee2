#include "rsg/sim/panda.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "rsg/sim/joint_trajectory.hpp"

namespace rsg::sim {
namespace {

using panda::Vector7d;

constexpr double kTolerance = 1e-4;

TEST(PandaKinematics, ZeroPoseStretchesUpright) {
  // All joints at 0: the arm points up, the flange 0.088 m forward of the base axis and
  // 0.333 + 0.316 + 0.384 - 0.107 m high (joint 7's frame points down), the hand below it.
  const panda::Kinematics kinematics = panda::forward_kinematics(Vector7d::Zero());
  EXPECT_TRUE(kinematics.flange.translation().isApprox(Eigen::Vector3d(0.088, 0, 0.926), kTolerance));
  EXPECT_TRUE(kinematics.end_effector.translation().isApprox(Eigen::Vector3d(0.088, 0, 0.8226), kTolerance));
}

TEST(PandaKinematics, ReadyPoseMatchesFranka) {
  const panda::Kinematics kinematics = panda::forward_kinematics(eigen::joints(panda::kReadyPose));
  std::cerr << kinematics.flange.matrix() << "\n\n" << kinematics.end_effector.matrix() << "\n";
}

}  // namespace
}  // namespace rsg::sim
