#include "rsg/sim/panda.hpp"

namespace rsg::sim::panda {
namespace {

// Modified DH parameters (Craig): frame i is reached by RotX(alpha) TransX(a) RotZ(q_i) TransZ(d).
struct DhRow {
  double a, d, alpha;
};
constexpr std::array<DhRow, kJoints> kDh = {{
    {0, 0.333, 0},
    {0, 0, -EIGEN_PI / 2},
    {0, 0.316, EIGEN_PI / 2},
    {0.0825, 0, EIGEN_PI / 2},
    {-0.0825, 0.384, -EIGEN_PI / 2},
    {0, 0, EIGEN_PI / 2},
    {0.088, 0, EIGEN_PI / 2},
}};
constexpr double kFlangeOffset = 0.107;
constexpr double kHandTcpOffset = 0.1034;

// Each link a point mass at the origin of the next joint's frame (masses after Gaz et al., 2019), the
// hand one at its centre of mass. Good enough for torques of the right size and sign.
constexpr std::array<double, kJoints> kLinkMass = {4.971, 0.647, 3.229, 3.588, 1.226, 1.667, 0.735};
const Eigen::Vector3d kGravity(0, 0, -9.81);

Eigen::Isometry3d dh_transform(const DhRow& row, double q) {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.rotate(Eigen::AngleAxisd(row.alpha, Eigen::Vector3d::UnitX()));
  transform.translate(Eigen::Vector3d(row.a, 0, 0));
  transform.rotate(Eigen::AngleAxisd(q, Eigen::Vector3d::UnitZ()));
  transform.translate(Eigen::Vector3d(0, 0, row.d));
  return transform;
}

}  // namespace

Eigen::Isometry3d flange_to_end_effector() {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.translate(Eigen::Vector3d(0, 0, kHandTcpOffset));
  transform.rotate(Eigen::AngleAxisd(-EIGEN_PI / 4, Eigen::Vector3d::UnitZ()));
  return transform;
}

Kinematics forward_kinematics(const Vector7d& q) {
  Kinematics result;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (std::size_t i = 0; i < kJoints; ++i) {
    pose = pose * dh_transform(kDh[i], q[static_cast<Eigen::Index>(i)]);
    result.joint[i] = pose;
  }
  result.flange = pose * Eigen::Translation3d(0, 0, kFlangeOffset);
  result.end_effector = result.flange * flange_to_end_effector();
  return result;
}

Vector6d Kinematics::twist(const Vector7d& dq) const {
  const Eigen::Vector3d tip = end_effector.translation();
  Vector6d result = Vector6d::Zero();
  for (std::size_t i = 0; i < kJoints; ++i) {
    const Eigen::Vector3d axis = joint[i].linear().col(2);
    const double rate = dq[static_cast<Eigen::Index>(i)];
    result.head<3>() += axis.cross(tip - joint[i].translation()) * rate;
    result.tail<3>() += axis * rate;
  }
  return result;
}

Vector7d Kinematics::gravity_torque() const {
  // Joint i holds the weight of every mass beyond it: tau_i = -z_i . sum_j (p_j - p_i) x (m_j g).
  // Joint j's point mass sits at the origin of the next frame (the last one and the hand at the flange).
  std::array<Eigen::Vector3d, kJoints + 1> mass_position;
  std::array<double, kJoints + 1> mass;
  for (std::size_t j = 0; j < kJoints; ++j) {
    mass_position[j] = j + 1 < kJoints ? joint[j + 1].translation() : flange.translation();
    mass[j] = kLinkMass[j];
  }
  mass_position[kJoints] = flange * eigen::vector3(kHandCentreOfMass);
  mass[kJoints] = kHandMass;

  Vector7d torque = Vector7d::Zero();
  for (std::size_t i = 0; i < kJoints; ++i) {
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    for (std::size_t j = i; j < mass.size(); ++j)
      moment += (mass_position[j] - joint[i].translation()).cross(mass[j] * kGravity);
    torque[static_cast<Eigen::Index>(i)] = -joint[i].linear().col(2).dot(moment);
  }
  return torque;
}

}  // namespace rsg::sim::panda
