// The Franka Emika Panda as the simulator models it: published limits and kinematics, plus a crude
// point-mass dynamics model that gives torques of the right size and sign (not identification-grade).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstddef>

#include "rsg/wire/eigen.hpp"

namespace rsg::tools::sim::panda {

using wire::eigen::Vector6d;
using wire::eigen::Vector7d;

inline constexpr std::size_t kJoints = 7;

/// Joint limits from Franka's datasheet ("Limits for Panda"), rad, rad/s, rad/s^2.
using JointArray = std::array<double, kJoints>;
inline constexpr JointArray kPositionMin = {-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973};
inline constexpr JointArray kPositionMax = {2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973};
inline constexpr JointArray kVelocityMax = {2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61};
inline constexpr JointArray kAccelerationMax = {15, 7.5, 10, 12.5, 15, 20, 20};

/// Franka's "ready" configuration, the centre of the simulated motion.
inline constexpr JointArray kReadyPose = {0, -EIGEN_PI / 4, 0,           -3 * EIGEN_PI / 4,
                                          0, EIGEN_PI / 2,  EIGEN_PI / 4};

/// The Franka Hand, the end effector the simulated robot is configured with (libfranka's defaults).
inline constexpr double kHandMass = 0.73;                                     // kg
inline constexpr std::array<double, 3> kHandCentreOfMass = {-0.01, 0, 0.03};  // m, flange frame
inline constexpr std::array<double, 9> kHandInertia = {0.001, 0, 0, 0, 0.0025, 0, 0, 0, 0.0017};  // kg m^2

/// End effector in the flange frame for the Franka Hand: turned -45 deg about z, TCP 0.1034 m out.
Eigen::Isometry3d flange_to_end_effector();

/// Every frame of the kinematic chain for one joint configuration, in the base frame O.
struct Kinematics {
  /// O_T_i of joint i's frame (its z axis is the joint axis), i = 0..6.
  std::array<Eigen::Isometry3d, kJoints> joint;
  Eigen::Isometry3d flange;        ///< O_T_F
  Eigen::Isometry3d end_effector;  ///< O_T_EE = O_T_F * F_T_EE

  /// Linear and angular velocity of the end effector in O for joint velocities `dq`.
  Vector6d twist(const Vector7d& dq) const;
  /// Time derivative of `twist` while the joints move with `dq` and accelerate with `ddq`.
  Vector6d twist_rate(const Vector7d& dq, const Vector7d& ddq) const;
  /// Joint torques that hold the arm (with the hand) against gravity.
  Vector7d gravity_torque() const;
  /// Time derivative of `gravity_torque` while the joints move with `dq`.
  Vector7d gravity_torque_rate(const Vector7d& dq) const;

  Eigen::Vector3d axis(std::size_t i) const { return joint[i].linear().col(2); }
  Eigen::Vector3d origin(std::size_t i) const { return joint[i].translation(); }
  /// Velocity of the point `x` fixed to the link after joint `joints - 1` (moved by joints 0..joints-1).
  Eigen::Vector3d point_velocity(const Eigen::Vector3d& x, std::size_t joints, const Vector7d& dq) const;
};

/// Forward kinematics from the modified (Craig) DH parameters Franka publishes.
Kinematics forward_kinematics(const Vector7d& q);

}  // namespace rsg::tools::sim::panda
