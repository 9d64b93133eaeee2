#include "tools/sim/panda_model.hpp"

#include <array>
#include <cstring>
#include <initializer_list>

#include "tools/sim/panda.hpp"

namespace rsg::tools::sim {
namespace {

using panda::Vector6d;
using panda::Vector7d;

// Effective joint inertias for the inertial part of the torques (kg m^2): the order of magnitude of
// the Panda's mass-matrix diagonal around the ready pose.
const Vector7d kJointInertia = (Vector7d() << 0.6, 1.8, 0.5, 0.6, 0.03, 0.04, 0.01).finished();
// Joint stiffness between motor and link (Nm/rad): the motor leads the link by tau / K.
constexpr double kJointStiffness = 2.0e4;
constexpr std::uint64_t kRobotModeMove = 2;
constexpr double kCommandSuccessRate = 1.0;

// Writes into the selected fields of a StateValues, and skips the others.
class FieldWriter {
 public:
  FieldWriter(const wire::Selection& wanted, wire::StateValues& out) : wanted_(wanted), out_(out) {}

  bool wants(std::initializer_list<wire::Field> fields) const {
    for (wire::Field field : fields)
      if (wanted_.contains(field)) return true;
    return false;
  }
  template <class Matrix>
  void put(wire::Field field, const Eigen::MatrixBase<Matrix>& value) {
    if (!wanted_.contains(field)) return;
    Eigen::Map<Eigen::Matrix<double, Matrix::RowsAtCompileTime, Matrix::ColsAtCompileTime>>(
        out_.doubles(field).data()) = value;
  }
  void put(wire::Field field, double value) {
    if (wanted_.contains(field)) out_.doubles(field)[0] = value;
  }
  void put_integer(wire::Field field, std::uint64_t value) {
    if (wanted_.contains(field)) out_.set_integer(field, value);
  }
  void put_zero(wire::Field field) {
    if (wanted_.contains(field))
      std::memset(wire::StateValues::layout().locate(out_.storage(), field), 0,
                  wire::info(field).value_bytes());
  }

 private:
  const wire::Selection& wanted_;
  wire::StateValues& out_;
};

// Fields that are zero on a robot moving freely: nothing touches it and nothing has gone wrong.
constexpr std::array kRestingFields = {
    wire::Field::m_load,
    wire::Field::I_load,
    wire::Field::F_x_Cload,
    wire::Field::joint_contact,
    wire::Field::cartesian_contact,
    wire::Field::joint_collision,
    wire::Field::cartesian_collision,
    wire::Field::tau_ext_hat_filtered,
    wire::Field::O_F_ext_hat_K,
    wire::Field::K_F_ext_hat_K,
    wire::Field::current_errors,
    wire::Field::last_motion_errors,
};

// libfranka's elbow: [0] the position of joint 3, [1] the sign of joint 4 (always -1 on a Panda).
Eigen::Vector2d elbow(const Vector7d& q) { return {q[2], q[3] < 0 ? -1.0 : 1.0}; }
// An elbow derivative: [0] that of joint 3, [1] 0 because the sign never changes continuously.
Eigen::Vector2d elbow_rate(const Vector7d& rate) { return {rate[2], 0}; }

}  // namespace

void PandaModel::fill(std::chrono::nanoseconds since_start, const wire::Selection& wanted,
                      wire::StateValues& out) const {
  const double t = std::chrono::duration<double>(since_start).count();
  FieldWriter writer(wanted, out);
  const JointState measured = trajectory_.at(t);
  const JointState desired = trajectory_.at(t + kDesiredLeadSeconds);

  writer.put(wire::Field::F_T_EE, panda::flange_to_end_effector().matrix());
  writer.put(wire::Field::EE_T_K, Eigen::Matrix4d::Identity());
  writer.put(wire::Field::m_ee, panda::kHandMass);
  writer.put(wire::Field::I_ee, wire::eigen::inertia(panda::kHandInertia));
  writer.put(wire::Field::F_x_Cee, wire::eigen::vector3(panda::kHandCentreOfMass));
  for (wire::Field field : kRestingFields) writer.put_zero(field);
  // Without a load, the total is the hand alone.
  writer.put(wire::Field::m_total, panda::kHandMass);
  writer.put(wire::Field::I_total, wire::eigen::inertia(panda::kHandInertia));
  writer.put(wire::Field::F_x_Ctotal, wire::eigen::vector3(panda::kHandCentreOfMass));
  writer.put(wire::Field::elbow, elbow(measured.position));
  writer.put(wire::Field::elbow_d, elbow(desired.position));
  writer.put(wire::Field::elbow_c, elbow(desired.position));
  writer.put(wire::Field::delbow_c, elbow_rate(desired.velocity));
  writer.put(wire::Field::ddelbow_c, elbow_rate(desired.acceleration));
  writer.put(wire::Field::tau_J_d, kJointInertia.cwiseProduct(desired.acceleration));
  writer.put(wire::Field::q, measured.position);
  writer.put(wire::Field::q_d, desired.position);
  writer.put(wire::Field::dq, measured.velocity);
  writer.put(wire::Field::dq_d, desired.velocity);
  writer.put(wire::Field::ddq_d, desired.acceleration);
  writer.put(wire::Field::control_command_success_rate, kCommandSuccessRate);
  writer.put_integer(wire::Field::robot_mode, kRobotModeMove);
  writer.put_integer(
      wire::Field::time,
      static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::milliseconds>(since_start).count()));

  // Kinematics are the expensive part: only for the fields that need them.
  if (writer.wants({wire::Field::O_T_EE, wire::Field::tau_J, wire::Field::dtau_J, wire::Field::theta,
                    wire::Field::dtheta})) {
    const panda::Kinematics kinematics = panda::forward_kinematics(measured.position);
    // Link-side torque: holding the arm against gravity plus accelerating it.
    const Vector7d torque = kinematics.gravity_torque() + kJointInertia.cwiseProduct(measured.acceleration);
    const Vector7d torque_rate =
        kinematics.gravity_torque_rate(measured.velocity) + kJointInertia.cwiseProduct(measured.jerk);
    writer.put(wire::Field::O_T_EE, kinematics.end_effector.matrix());
    writer.put(wire::Field::tau_J, torque);
    writer.put(wire::Field::dtau_J, torque_rate);
    writer.put(wire::Field::theta, measured.position + torque / kJointStiffness);
    writer.put(wire::Field::dtheta, measured.velocity + torque_rate / kJointStiffness);
  }
  if (writer.wants({wire::Field::O_T_EE_d, wire::Field::O_T_EE_c, wire::Field::O_dP_EE_d,
                    wire::Field::O_dP_EE_c, wire::Field::O_ddP_EE_c})) {
    const panda::Kinematics kinematics = panda::forward_kinematics(desired.position);
    const Vector6d twist = kinematics.twist(desired.velocity);
    writer.put(wire::Field::O_T_EE_d, kinematics.end_effector.matrix());
    writer.put(wire::Field::O_dP_EE_d, twist);
    // A joint-space motion commands the desired trajectory as it is.
    writer.put(wire::Field::O_T_EE_c, kinematics.end_effector.matrix());
    writer.put(wire::Field::O_dP_EE_c, twist);
    writer.put(wire::Field::O_ddP_EE_c, kinematics.twist_rate(desired.velocity, desired.acceleration));
  }
}

}  // namespace rsg::tools::sim
