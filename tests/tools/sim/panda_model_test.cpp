// The robot state the simulator fills: consistent with the motion, the spec and itself.
#include "tools/sim/panda_model.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "rsg/wire/frame.hpp"
#include "tools/sim/panda.hpp"

namespace rsg::tools::sim {
namespace {

using namespace std::chrono_literals;
using panda::Vector6d;
using panda::Vector7d;

Eigen::Map<const Vector7d> joints_of(const wire::StateValues& values, wire::Field field) {
  return Eigen::Map<const Vector7d>(values.doubles(field).data());
}
Eigen::Map<const Vector6d> vector6_of(const wire::StateValues& values, wire::Field field) {
  return Eigen::Map<const Vector6d>(values.doubles(field).data());
}
Eigen::Map<const Eigen::Matrix4d> pose_of(const wire::StateValues& values, wire::Field field) {
  return Eigen::Map<const Eigen::Matrix4d>(values.doubles(field).data());
}

wire::StateValues state_at(const PandaModel& model, std::chrono::nanoseconds since_start) {
  wire::StateValues values;
  values.selection = wire::Selection::all();
  model.fill(since_start, values.selection, values);
  return values;
}

TEST(PandaModel, MeasuredPoseIsTheKinematicsOfMeasuredJoints) {
  const PandaModel model(1);
  const wire::StateValues values = state_at(model, 1234ms);
  const panda::Kinematics kinematics = panda::forward_kinematics(joints_of(values, wire::Field::q));
  EXPECT_TRUE(pose_of(values, wire::Field::O_T_EE).isApprox(kinematics.end_effector.matrix(), 1e-12));
  const Eigen::Matrix3d rotation = pose_of(values, wire::Field::O_T_EE).topLeftCorner<3, 3>();
  EXPECT_TRUE((rotation * rotation.transpose()).isIdentity(1e-12));
  EXPECT_EQ(pose_of(values, wire::Field::O_T_EE).row(3), Eigen::RowVector4d(0, 0, 0, 1));
  EXPECT_TRUE(pose_of(values, wire::Field::F_T_EE).isApprox(panda::flange_to_end_effector().matrix()));
}

TEST(PandaModel, DesiredLeadsMeasuredByOneCycle) {
  const PandaModel model(2);
  const double t = 3.25;
  const wire::StateValues values = state_at(model, 3250ms);
  const JointState desired = model.trajectory().at(t + PandaModel::kDesiredLeadSeconds);
  EXPECT_TRUE(joints_of(values, wire::Field::q).isApprox(model.trajectory().at(t).position));
  EXPECT_TRUE(joints_of(values, wire::Field::dq).isApprox(model.trajectory().at(t).velocity));
  EXPECT_TRUE(joints_of(values, wire::Field::q_d).isApprox(desired.position));
  EXPECT_TRUE(joints_of(values, wire::Field::dq_d).isApprox(desired.velocity));
  EXPECT_TRUE(joints_of(values, wire::Field::ddq_d).isApprox(desired.acceleration));
  EXPECT_TRUE(pose_of(values, wire::Field::O_T_EE_d)
                  .isApprox(panda::forward_kinematics(desired.position).end_effector.matrix(), 1e-12));
}

TEST(PandaModel, RatesMatchDifferencesOfTheirQuantities) {
  const PandaModel model(3);
  constexpr auto kStep = 10us;
  const double step_seconds = 1e-5;
  for (auto t = 100ms; t < 20s; t += 1700ms) {
    const wire::StateValues now = state_at(model, t);
    const wire::StateValues ahead = state_at(model, t + kStep);
    const wire::StateValues behind = state_at(model, t - kStep);
    const auto difference = [&](wire::Field field) {
      Eigen::VectorXd result(wire::info(field).count);
      for (std::size_t i = 0; i < info(field).count; ++i)
        result[static_cast<Eigen::Index>(i)] =
            (ahead.doubles(field)[i] - behind.doubles(field)[i]) / (2 * step_seconds);
      return result;
    };
    EXPECT_TRUE(joints_of(now, wire::Field::dq).isApprox(difference(wire::Field::q), 1e-6));
    EXPECT_TRUE(joints_of(now, wire::Field::ddq_d).isApprox(difference(wire::Field::dq_d), 1e-6));
    EXPECT_LT((joints_of(now, wire::Field::dtau_J) - difference(wire::Field::tau_J)).cwiseAbs().maxCoeff(),
              1e-4);
    EXPECT_LT((joints_of(now, wire::Field::dtheta) - difference(wire::Field::theta)).cwiseAbs().maxCoeff(),
              1e-6);
    EXPECT_LT(
        (vector6_of(now, wire::Field::O_ddP_EE_c) - difference(wire::Field::O_dP_EE_c)).cwiseAbs().maxCoeff(),
        1e-5);
  }
}

TEST(PandaModel, ElbowFollowsJointsThreeAndFour) {
  const PandaModel model(4);
  const wire::StateValues values = state_at(model, 777ms);
  EXPECT_EQ(values.doubles(wire::Field::elbow)[0], values.doubles(wire::Field::q)[2]);
  EXPECT_EQ(values.doubles(wire::Field::elbow)[1], -1.0);  // joint 4 is always negative on a Panda
  EXPECT_EQ(values.doubles(wire::Field::elbow_d)[0], values.doubles(wire::Field::q_d)[2]);
  EXPECT_EQ(values.doubles(wire::Field::delbow_c)[0], values.doubles(wire::Field::dq_d)[2]);
  EXPECT_EQ(values.doubles(wire::Field::ddelbow_c)[0], values.doubles(wire::Field::ddq_d)[2]);
}

TEST(PandaModel, HealthyRobotMovingFreely) {
  const PandaModel model(5);
  const wire::StateValues values = state_at(model, 2s);
  EXPECT_EQ(values.integer(wire::Field::robot_mode), 2U);  // move
  EXPECT_EQ(values.integer(wire::Field::current_errors), 0U);
  EXPECT_EQ(values.integer(wire::Field::last_motion_errors), 0U);
  EXPECT_EQ(values.doubles(wire::Field::control_command_success_rate)[0], 1.0);
  for (wire::Field field :
       {wire::Field::joint_contact, wire::Field::cartesian_contact, wire::Field::tau_ext_hat_filtered,
        wire::Field::O_F_ext_hat_K, wire::Field::K_F_ext_hat_K})
    for (double value : values.doubles(field)) EXPECT_EQ(value, 0.0) << wire::info(field).name;
  EXPECT_GT(values.doubles(wire::Field::m_ee)[0], 0.0);
  EXPECT_EQ(values.doubles(wire::Field::m_total)[0],
            values.doubles(wire::Field::m_ee)[0] + values.doubles(wire::Field::m_load)[0]);
}

TEST(PandaModel, TimeIsWholeMillisecondsSinceStart) {
  const PandaModel model(6);
  EXPECT_EQ(state_at(model, 0ns).integer(wire::Field::time), 0U);
  EXPECT_EQ(state_at(model, 999us).integer(wire::Field::time), 0U);
  EXPECT_EQ(state_at(model, 1ms).integer(wire::Field::time), 1U);
  EXPECT_EQ(state_at(model, 3600s + 20us).integer(wire::Field::time), 3600000U);
}

TEST(PandaModel, WritesOnlyTheSelectedFields) {
  const PandaModel model(7);
  wire::StateValues values;
  for (const wire::FieldInfo& field : wire::kFields)
    if (field.type == wire::ElementType::kFloat64)
      for (double& value : values.doubles(field.id())) value = -12345;
  wire::Selection joints;
  joints.add(wire::Field::q);
  joints.add(wire::Field::dq);
  model.fill(1s, joints, values);
  for (const wire::FieldInfo& field : wire::kFields) {
    if (field.type != wire::ElementType::kFloat64) continue;
    const bool untouched = values.doubles(field.id())[0] == -12345;
    EXPECT_EQ(untouched, !joints.contains(field.id())) << field.name;
  }
}

TEST(PandaModel, EveryStateEncodesToAValidFrame) {
  const PandaModel model(8);
  std::array<std::uint8_t, wire::kMaxFrameBytes> frame{};
  for (auto t = 0ms; t < 60s; t += 997ms) {
    const wire::StateValues values = state_at(model, t);
    const wire::EncodeResult encoded =
        encode(0, values.selection, values.storage(), wire::StateValues::layout(), frame);
    ASSERT_TRUE(encoded) << encoded.error.message();
    EXPECT_TRUE(wire::decode(std::span(frame).first(encoded.size)));
  }
}

}  // namespace
}  // namespace rsg::tools::sim
