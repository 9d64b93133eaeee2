// Kinematics and trajectory of the simulated Panda against known poses and their own derivatives.
#include "tools/sim/panda.hpp"

#include <gtest/gtest.h>

#include "tools/sim/joint_trajectory.hpp"

namespace rsg::tools::sim {
namespace {

using panda::Vector6d;
using panda::Vector7d;

constexpr double kPoseTolerance = 1e-4;  // m; the published poses are given to 0.1 mm

Eigen::Vector3d position(const Eigen::Isometry3d& pose) { return pose.translation(); }

TEST(PandaKinematics, ZeroPoseStandsUpright) {
  // All joints at 0: the arm points up; the flange is a = 0.088 m forward of the base axis at
  // 0.333 + 0.316 + 0.384 - 0.107 m (the last frame points down), the Franka Hand TCP 0.1034 m below.
  const panda::Kinematics kinematics = panda::forward_kinematics(Vector7d::Zero());
  EXPECT_TRUE(position(kinematics.flange).isApprox(Eigen::Vector3d(0.088, 0, 0.926), kPoseTolerance));
  EXPECT_TRUE(position(kinematics.end_effector).isApprox(Eigen::Vector3d(0.088, 0, 0.8226), kPoseTolerance));
}

TEST(PandaKinematics, ReadyPoseMatchesFranka) {
  // libfranka reports O_T_EE = [0.3069, 0, 0.4869] pointing down, hand axes aligned with the base,
  // in the ready pose with the Franka Hand.
  const panda::Kinematics kinematics = panda::forward_kinematics(wire::eigen::joints(panda::kReadyPose));
  EXPECT_NEAR(kinematics.flange.translation().x(), 0.3069, kPoseTolerance);
  EXPECT_NEAR(kinematics.flange.translation().y(), 0.0, kPoseTolerance);
  EXPECT_NEAR(kinematics.flange.translation().z(), 0.5903, kPoseTolerance);
  EXPECT_TRUE(position(kinematics.end_effector).isApprox(Eigen::Vector3d(0.3069, 0, 0.4869), kPoseTolerance));
  EXPECT_TRUE(kinematics.end_effector.linear().isApprox(
      Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix(), 1e-12));
}

TEST(PandaKinematics, FlangeToEndEffectorIsTheFrankaHand) {
  const Eigen::Isometry3d hand = panda::flange_to_end_effector();
  EXPECT_NEAR(hand.translation().z(), 0.1034, 1e-12);
  EXPECT_NEAR(hand.linear()(0, 0), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(hand.linear()(1, 0), -std::sqrt(0.5), 1e-12);  // -45 degrees about z
}

TEST(PandaKinematics, FirstJointFeelsNoGravity) {
  // Joint 1's axis is vertical, so weight has no moment about it in any pose.
  const JointTrajectory trajectory(7);
  for (double t = 0; t < 20; t += 0.37)
    EXPECT_NEAR(panda::forward_kinematics(trajectory.at(t).position).gravity_torque()[0], 0.0, 1e-9);
}

TEST(PandaKinematics, ShoulderHoldsTheArmInTheReadyPose) {
  // Leaning forward, joint 2 carries most of the ~18 kg arm's moment: tens of Nm.
  const Vector7d torque = panda::forward_kinematics(wire::eigen::joints(panda::kReadyPose)).gravity_torque();
  EXPECT_GT(std::abs(torque[1]), 5.0);
  EXPECT_LT(std::abs(torque[1]), 80.0);
}

// Rates along the trajectory agree with central differences of the quantities themselves.
class AlongTrajectory : public ::testing::Test {
 protected:
  static constexpr double kStep = 1e-5;
  const JointTrajectory trajectory_{3};

  panda::Kinematics at(double t) const { return panda::forward_kinematics(trajectory_.at(t).position); }
};

TEST_F(AlongTrajectory, TwistIsTheRateOfThePose) {
  for (double t = 0.5; t < 30; t += 1.3) {
    const Vector6d twist = at(t).twist(trajectory_.at(t).velocity);
    const Eigen::Vector3d velocity =
        (position(at(t + kStep).end_effector) - position(at(t - kStep).end_effector)) / (2 * kStep);
    EXPECT_TRUE(twist.head<3>().isApprox(velocity, 1e-6)) << "t = " << t;
    // Angular velocity: the skew-symmetric part of dR/dt R^T.
    const Eigen::Matrix3d rotation_rate =
        (at(t + kStep).end_effector.linear() - at(t - kStep).end_effector.linear()) / (2 * kStep);
    const Eigen::Matrix3d skew = rotation_rate * at(t).end_effector.linear().transpose();
    EXPECT_TRUE(twist.tail<3>().isApprox(Eigen::Vector3d(skew(2, 1), skew(0, 2), skew(1, 0)), 1e-6))
        << "t = " << t;
  }
}

TEST_F(AlongTrajectory, TwistRateIsTheRateOfTheTwist) {
  for (double t = 0.5; t < 30; t += 1.3) {
    const JointState state = trajectory_.at(t);
    const Vector6d difference = (at(t + kStep).twist(trajectory_.at(t + kStep).velocity) -
                                 at(t - kStep).twist(trajectory_.at(t - kStep).velocity)) /
                                (2 * kStep);
    EXPECT_TRUE(at(t).twist_rate(state.velocity, state.acceleration).isApprox(difference, 1e-5))
        << "t = " << t;
  }
}

TEST_F(AlongTrajectory, GravityTorqueRateIsTheRateOfTheGravityTorque) {
  for (double t = 0.5; t < 30; t += 1.3) {
    const Vector7d difference =
        (at(t + kStep).gravity_torque() - at(t - kStep).gravity_torque()) / (2 * kStep);
    const Vector7d rate = at(t).gravity_torque_rate(trajectory_.at(t).velocity);
    EXPECT_LT((rate - difference).cwiseAbs().maxCoeff(), 1e-5) << "t = " << t;
  }
}

TEST(JointTrajectory, StaysStrictlyInsideTheLimitsForAnHour) {
  for (std::uint64_t seed : {1, 42, 1234567}) {
    const JointTrajectory trajectory(seed);
    for (double t = 0; t < 3600; t += 0.02) {
      const JointState state = trajectory.at(t);
      ASSERT_TRUE((state.position.array() > wire::eigen::joints(panda::kPositionMin).array()).all())
          << "t = " << t;
      ASSERT_TRUE((state.position.array() < wire::eigen::joints(panda::kPositionMax).array()).all())
          << "t = " << t;
      ASSERT_TRUE(
          (state.velocity.cwiseAbs().array() < wire::eigen::joints(panda::kVelocityMax).array()).all());
      ASSERT_TRUE(
          (state.acceleration.cwiseAbs().array() < wire::eigen::joints(panda::kAccelerationMax).array())
              .all());
    }
  }
}

TEST(JointTrajectory, DerivativesAreThoseOfThePosition) {
  const JointTrajectory trajectory(11);
  constexpr double kStep = 1e-5;
  for (double t = 0; t < 100; t += 0.77) {
    const JointState state = trajectory.at(t);
    const JointState ahead = trajectory.at(t + kStep);
    const JointState behind = trajectory.at(t - kStep);
    EXPECT_TRUE(state.velocity.isApprox((ahead.position - behind.position) / (2 * kStep), 1e-6));
    EXPECT_TRUE(state.acceleration.isApprox((ahead.velocity - behind.velocity) / (2 * kStep), 1e-6));
    EXPECT_TRUE(state.jerk.isApprox((ahead.acceleration - behind.acceleration) / (2 * kStep), 1e-6));
  }
}

TEST(JointTrajectory, SeedChoosesTheMotion) {
  EXPECT_EQ(JointTrajectory(5).at(12.5).position, JointTrajectory(5).at(12.5).position);
  EXPECT_NE(JointTrajectory(5).at(12.5).position, JointTrajectory(6).at(12.5).position);
}

TEST(JointTrajectory, ActuallyMoves) {
  const JointTrajectory trajectory(1);
  EXPECT_GT((trajectory.at(0).position - trajectory.at(2.5).position).cwiseAbs().maxCoeff(), 0.05);
}

}  // namespace
}  // namespace rsg::tools::sim
