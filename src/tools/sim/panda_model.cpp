#include "panda_model.hpp"

#include <array>
#include <cstring>
#include <initializer_list>

#include "panda.hpp"

namespace rsg::sim {
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
  FieldWriter(const Selection& wanted, StateValues& out) : wanted_(wanted), out_(out) {}

  bool wants(std::initializer_list<Field> fields) const {
    for (Field field : fields)
      if (wanted_.contains(field)) return true;
    return false;
  }
  template <class Matrix>
  void put(Field field, const Eigen::MatrixBase<Matrix>& value) {
    if (!wanted_.contains(field)) return;
    Eigen::Map<Eigen::Matrix<double, Matrix::RowsAtCompileTime, Matrix::ColsAtCompileTime>>(
        out_.doubles(field).data()) = value;
  }
  void put(Field field, double value) {
    if (wanted_.contains(field)) out_.doubles(field)[0] = value;
  }
  void put_integer(Field field, std::uint64_t value) {
    if (wanted_.contains(field)) out_.set_integer(field, value);
  }
  void put_zero(Field field) {
    if (wanted_.contains(field))
      std::memset(StateValues::layout().locate(out_.storage(), field), 0, info(field).value_bytes());
  }

 private:
  const Selection& wanted_;
  StateValues& out_;
};

// Fields that are zero on a robot moving freely: nothing touches it and nothing has gone wrong.
constexpr std::array kRestingFields = {
    Field::m_load,
    Field::I_load,
    Field::F_x_Cload,
    Field::joint_contact,
    Field::cartesian_contact,
    Field::joint_collision,
    Field::cartesian_collision,
    Field::tau_ext_hat_filtered,
    Field::O_F_ext_hat_K,
    Field::K_F_ext_hat_K,
    Field::current_errors,
    Field::last_motion_errors,
};

// libfranka's elbow: [0] the position of joint 3, [1] the sign of joint 4 (always -1 on a Panda).
Eigen::Vector2d elbow(const Vector7d& q) { return {q[2], q[3] < 0 ? -1.0 : 1.0}; }
// An elbow derivative: [0] that of joint 3, [1] 0 because the sign never changes continuously.
Eigen::Vector2d elbow_rate(const Vector7d& rate) { return {rate[2], 0}; }

}  // namespace

void PandaModel::fill(std::chrono::nanoseconds since_start, const Selection& wanted, StateValues& out) const {
  const double t = std::chrono::duration<double>(since_start).count();
  FieldWriter writer(wanted, out);
  const JointState measured = trajectory_.at(t);
  const JointState desired = trajectory_.at(t + kDesiredLeadSeconds);

  writer.put(Field::F_T_EE, panda::flange_to_end_effector().matrix());
  writer.put(Field::EE_T_K, Eigen::Matrix4d::Identity());
  writer.put(Field::m_ee, panda::kHandMass);
  writer.put(Field::I_ee, eigen::inertia(panda::kHandInertia));
  writer.put(Field::F_x_Cee, eigen::vector3(panda::kHandCentreOfMass));
  for (Field field : kRestingFields) writer.put_zero(field);
  // Without a load, the total is the hand alone.
  writer.put(Field::m_total, panda::kHandMass);
  writer.put(Field::I_total, eigen::inertia(panda::kHandInertia));
  writer.put(Field::F_x_Ctotal, eigen::vector3(panda::kHandCentreOfMass));
  writer.put(Field::elbow, elbow(measured.position));
  writer.put(Field::elbow_d, elbow(desired.position));
  writer.put(Field::elbow_c, elbow(desired.position));
  writer.put(Field::delbow_c, elbow_rate(desired.velocity));
  writer.put(Field::ddelbow_c, elbow_rate(desired.acceleration));
  writer.put(Field::tau_J_d, kJointInertia.cwiseProduct(desired.acceleration));
  writer.put(Field::q, measured.position);
  writer.put(Field::q_d, desired.position);
  writer.put(Field::dq, measured.velocity);
  writer.put(Field::dq_d, desired.velocity);
  writer.put(Field::ddq_d, desired.acceleration);
  writer.put(Field::control_command_success_rate, kCommandSuccessRate);
  writer.put_integer(Field::robot_mode, kRobotModeMove);
  writer.put_integer(
      Field::time,
      static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::milliseconds>(since_start).count()));

  // Kinematics are the expensive part: only for the fields that need them.
  if (writer.wants({Field::O_T_EE, Field::tau_J, Field::dtau_J, Field::theta, Field::dtheta})) {
    const panda::Kinematics kinematics = panda::forward_kinematics(measured.position);
    // Link-side torque: holding the arm against gravity plus accelerating it.
    const Vector7d torque = kinematics.gravity_torque() + kJointInertia.cwiseProduct(measured.acceleration);
    const Vector7d torque_rate =
        kinematics.gravity_torque_rate(measured.velocity) + kJointInertia.cwiseProduct(measured.jerk);
    writer.put(Field::O_T_EE, kinematics.end_effector.matrix());
    writer.put(Field::tau_J, torque);
    writer.put(Field::dtau_J, torque_rate);
    writer.put(Field::theta, measured.position + torque / kJointStiffness);
    writer.put(Field::dtheta, measured.velocity + torque_rate / kJointStiffness);
  }
  if (writer.wants(
          {Field::O_T_EE_d, Field::O_T_EE_c, Field::O_dP_EE_d, Field::O_dP_EE_c, Field::O_ddP_EE_c})) {
    const panda::Kinematics kinematics = panda::forward_kinematics(desired.position);
    const Vector6d twist = kinematics.twist(desired.velocity);
    writer.put(Field::O_T_EE_d, kinematics.end_effector.matrix());
    writer.put(Field::O_dP_EE_d, twist);
    // A joint-space motion commands the desired trajectory as it is.
    writer.put(Field::O_T_EE_c, kinematics.end_effector.matrix());
    writer.put(Field::O_dP_EE_c, twist);
    writer.put(Field::O_ddP_EE_c, kinematics.twist_rate(desired.velocity, desired.acceleration));
  }
}

}  // namespace rsg::sim
