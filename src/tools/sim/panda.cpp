#include "tools/sim/panda.hpp"

#include <cmath>

namespace rsg::tools::sim::panda {
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

constexpr std::array<double, kJoints> kLinkMass = {4.971, 0.647, 3.229, 3.588, 1.226, 1.667, 0.735};
const Eigen::Vector3d kGravity(0, 0, -9.81);

// The product RotX(alpha) TransX(a) RotZ(q) TransZ(d) written out: one sine and cosine per joint,
// which matters because the simulator evaluates the chain several times per frame at up to 50 kHz.
struct DhTrig {
  double cos_alpha, sin_alpha;
};
const std::array<DhTrig, kJoints>& dh_trig() {
  static const std::array<DhTrig, kJoints> table = [] {
    std::array<DhTrig, kJoints> trig;
    for (std::size_t i = 0; i < kJoints; ++i) trig[i] = {std::cos(kDh[i].alpha), std::sin(kDh[i].alpha)};
    return trig;
  }();
  return table;
}

Eigen::Isometry3d dh_transform(std::size_t joint, double q) {
  const DhRow& row = kDh[joint];
  const auto [cos_alpha, sin_alpha] = dh_trig()[joint];
  const double cos_q = std::cos(q);
  const double sin_q = std::sin(q);
  Eigen::Isometry3d transform;
  transform.linear() << cos_q, -sin_q, 0,                //
      cos_alpha * sin_q, cos_alpha * cos_q, -sin_alpha,  //
      sin_alpha * sin_q, sin_alpha * cos_q, cos_alpha;
  transform.translation() << row.a, -sin_alpha * row.d, cos_alpha * row.d;
  transform.makeAffine();
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
  // Plain 4x4 products: Eigen vectorises those, not the 3x3 blocks an Isometry product works on.
  for (std::size_t i = 0; i < kJoints; ++i) {
    pose.matrix() = pose.matrix() * dh_transform(i, q[static_cast<Eigen::Index>(i)]).matrix();
    result.joint[i] = pose;
  }
  result.flange = pose * Eigen::Translation3d(0, 0, kFlangeOffset);
  static const Eigen::Isometry3d kFlangeToEndEffector = flange_to_end_effector();
  result.end_effector.matrix() = result.flange.matrix() * kFlangeToEndEffector.matrix();
  return result;
}

Eigen::Vector3d Kinematics::point_velocity(const Eigen::Vector3d& x, std::size_t joints,
                                           const Vector7d& dq) const {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < joints; ++k)
    velocity += axis(k).cross(x - origin(k)) * dq[static_cast<Eigen::Index>(k)];
  return velocity;
}

Vector6d Kinematics::twist(const Vector7d& dq) const {
  const Eigen::Vector3d tip = end_effector.translation();
  Vector6d result = Vector6d::Zero();
  for (std::size_t i = 0; i < kJoints; ++i) {
    const double rate = dq[static_cast<Eigen::Index>(i)];
    result.head<3>() += axis(i).cross(tip - origin(i)) * rate;
    result.tail<3>() += axis(i) * rate;
  }
  return result;
}

Vector6d Kinematics::twist_rate(const Vector7d& dq, const Vector7d& ddq) const {
  // Differentiates each column z_i x (tip - p_i) and z_i of the Jacobian: z_i turns with the
  // angular velocity of the links before it, p_i moves with the joints before it.
  const Eigen::Vector3d tip = end_effector.translation();
  const Eigen::Vector3d tip_velocity = twist(dq).head<3>();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  Vector6d result = Vector6d::Zero();
  for (std::size_t i = 0; i < kJoints; ++i) {
    const double rate = dq[static_cast<Eigen::Index>(i)];
    const double acceleration = ddq[static_cast<Eigen::Index>(i)];
    const Eigen::Vector3d axis_rate = angular_velocity.cross(axis(i));
    const Eigen::Vector3d arm = tip - origin(i);
    const Eigen::Vector3d arm_rate = tip_velocity - point_velocity(origin(i), i, dq);
    result.head<3>() +=
        (axis_rate.cross(arm) + axis(i).cross(arm_rate)) * rate + axis(i).cross(arm) * acceleration;
    result.tail<3>() += axis_rate * rate + axis(i) * acceleration;
    angular_velocity += axis(i) * rate;
  }
  return result;
}

namespace {

struct PointMass {
  Eigen::Vector3d position;
  double mass;
  std::size_t moved_by;  // joints 0..moved_by-1 carry it
};

// Each link a point mass at the origin of the next joint's frame (masses after Gaz et al., 2019), the
// hand one at its centre of mass. Good enough for torques of the right size and sign.
std::array<PointMass, kJoints + 1> point_masses(const Kinematics& kinematics) {
  std::array<PointMass, kJoints + 1> masses;
  for (std::size_t j = 0; j < kJoints; ++j) {
    const Eigen::Vector3d at = j + 1 < kJoints ? kinematics.origin(j + 1) : kinematics.flange.translation();
    masses[j] = {at, kLinkMass[j], j + 1};
  }
  masses[kJoints] = {kinematics.flange * wire::eigen::vector3(kHandCentreOfMass), kHandMass, kJoints};
  return masses;
}

}  // namespace

Vector7d Kinematics::gravity_torque() const {
  // Joint i holds the weight of every mass it carries: tau_i = -z_i . sum_j (x_j - p_i) x (m_j g).
  const auto masses = point_masses(*this);
  Vector7d torque;
  for (std::size_t i = 0; i < kJoints; ++i) {
    Eigen::Vector3d first_moment = Eigen::Vector3d::Zero();
    for (const PointMass& point : masses)
      if (point.moved_by > i) first_moment += point.mass * (point.position - origin(i));
    torque[static_cast<Eigen::Index>(i)] = -axis(i).dot(first_moment.cross(kGravity));
  }
  return torque;
}

Vector7d Kinematics::gravity_torque_rate(const Vector7d& dq) const {
  // The product rule on gravity_torque: z_i turns, and the masses move relative to p_i.
  const auto masses = point_masses(*this);
  std::array<Eigen::Vector3d, masses.size()> mass_velocity;
  for (std::size_t j = 0; j < masses.size(); ++j)
    mass_velocity[j] = point_velocity(masses[j].position, masses[j].moved_by, dq);

  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  Vector7d rate;
  for (std::size_t i = 0; i < kJoints; ++i) {
    const Eigen::Vector3d axis_rate = angular_velocity.cross(axis(i));
    const Eigen::Vector3d origin_velocity = point_velocity(origin(i), i, dq);
    Eigen::Vector3d first_moment = Eigen::Vector3d::Zero();
    Eigen::Vector3d first_moment_rate = Eigen::Vector3d::Zero();
    for (std::size_t j = 0; j < masses.size(); ++j) {
      if (masses[j].moved_by <= i) continue;
      first_moment += masses[j].mass * (masses[j].position - origin(i));
      first_moment_rate += masses[j].mass * (mass_velocity[j] - origin_velocity);
    }
    rate[static_cast<Eigen::Index>(i)] =
        -axis_rate.dot(first_moment.cross(kGravity)) - axis(i).dot(first_moment_rate.cross(kGravity));
    angular_velocity += axis(i) * dq[static_cast<Eigen::Index>(i)];
  }
  return rate;
}

}  // namespace rsg::tools::sim::panda
