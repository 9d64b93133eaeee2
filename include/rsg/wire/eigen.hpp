// Zero-copy Eigen views of a robot state's arrays: a RobotState sample's members, the arrays of the
// wire layer's field table (the frame's layout; no DDS involved). Link rsg::eigen (find_package(rsg
// COMPONENTS eigen)), which brings Eigen; rsg's other libraries do not need Eigen.
//
//   const Eigen::Vector3d position = rsg::wire::eigen::pose(sample.O_T_EE()).block<3, 1>(0, 3);
//   rsg::wire::eigen::joints(sample.q())   // Map<const Vector7d>, no copy
//
// The frame stores matrices column-major, as Eigen does by default, so a Map is the matrix:
// the translation of a pose is at elements 12..14.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

namespace rsg::wire::eigen {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Vector7d = Eigen::Matrix<double, 7, 1>;

/// 4x4 homogeneous pose (O_T_EE, O_T_EE_d, F_T_EE, EE_T_K, O_T_EE_c).
inline Eigen::Map<const Eigen::Matrix4d> pose(const std::array<double, 16>& m) {
  return Eigen::Map<const Eigen::Matrix4d>(m.data());
}
inline Eigen::Map<Eigen::Matrix4d> pose(std::array<double, 16>& m) {
  return Eigen::Map<Eigen::Matrix4d>(m.data());
}

/// The pose as a rigid transform. Eigen cannot map a Transform, so this is a 128-byte copy.
inline Eigen::Isometry3d isometry(const std::array<double, 16>& m) {
  Eigen::Isometry3d transform;
  transform.matrix() = pose(m);
  return transform;
}

/// 3x3 inertia tensor (I_ee, I_load, I_total).
inline Eigen::Map<const Eigen::Matrix3d> inertia(const std::array<double, 9>& m) {
  return Eigen::Map<const Eigen::Matrix3d>(m.data());
}
inline Eigen::Map<Eigen::Matrix3d> inertia(std::array<double, 9>& m) {
  return Eigen::Map<Eigen::Matrix3d>(m.data());
}

/// Centre of mass (F_x_Cee, F_x_Cload, F_x_Ctotal).
inline Eigen::Map<const Eigen::Vector3d> vector3(const std::array<double, 3>& v) {
  return Eigen::Map<const Eigen::Vector3d>(v.data());
}
inline Eigen::Map<Eigen::Vector3d> vector3(std::array<double, 3>& v) {
  return Eigen::Map<Eigen::Vector3d>(v.data());
}

/// Wrench or twist: force/linear (x, y, z) then torque/angular (x, y, z).
inline Eigen::Map<const Vector6d> vector6(const std::array<double, 6>& v) {
  return Eigen::Map<const Vector6d>(v.data());
}
inline Eigen::Map<Vector6d> vector6(std::array<double, 6>& v) { return Eigen::Map<Vector6d>(v.data()); }

/// Per-joint quantity (q, dq, tau_J, theta, ...).
inline Eigen::Map<const Vector7d> joints(const std::array<double, 7>& v) {
  return Eigen::Map<const Vector7d>(v.data());
}
inline Eigen::Map<Vector7d> joints(std::array<double, 7>& v) { return Eigen::Map<Vector7d>(v.data()); }

}  // namespace rsg::wire::eigen
