// The robot state the simulator fills: consistent with the motion, the spec and itself.
#include "panda_model.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "panda.hpp"
#include "rsg/wire/frame.hpp"

namespace rsg::sim {
namespace {

using namespace std::chrono_literals;
using panda::Vector6d;
using panda::Vector7d;

Eigen::Map<const Vector7d> joints_of(const StateValues& values, Field field) {
  return Eigen::Map<const Vector7d>(values.doubles(field).data());
}
Eigen::Map<const Vector6d> vector6_of(const StateValues& values, Field field) {
  return Eigen::Map<const Vector6d>(values.doubles(field).data());
}
Eigen::Map<const Eigen::Matrix4d> pose_of(const StateValues& values, Field field) {
  return Eigen::Map<const Eigen::Matrix4d>(values.doubles(field).data());
}

StateValues state_at(const PandaModel& model, std::chrono::nanoseconds since_start) {
  StateValues values;
  values.selection = Selection::all();
  model.fill(since_start, values.selection, values);
  return values;
}

TEST(PandaModel, MeasuredPoseIsTheKinematicsOfMeasuredJoints) {
  const PandaModel model(1);
  const StateValues values = state_at(model, 1234ms);
  const panda::Kinematics kinematics = panda::forward_kinematics(joints_of(values, Field::q));
  EXPECT_TRUE(pose_of(values, Field::O_T_EE).isApprox(kinematics.end_effector.matrix(), 1e-12));
  const Eigen::Matrix3d rotation = pose_of(values, Field::O_T_EE).topLeftCorner<3, 3>();
  EXPECT_TRUE((rotation * rotation.transpose()).isIdentity(1e-12));
  EXPECT_EQ(pose_of(values, Field::O_T_EE).row(3), Eigen::RowVector4d(0, 0, 0, 1));
  EXPECT_TRUE(pose_of(values, Field::F_T_EE).isApprox(panda::flange_to_end_effector().matrix()));
}

TEST(PandaModel, DesiredLeadsMeasuredByOneCycle) {
  const PandaModel model(2);
  const double t = 3.25;
  const StateValues values = state_at(model, 3250ms);
  const JointState desired = model.trajectory().at(t + PandaModel::kDesiredLeadSeconds);
  EXPECT_TRUE(joints_of(values, Field::q).isApprox(model.trajectory().at(t).position));
  EXPECT_TRUE(joints_of(values, Field::dq).isApprox(model.trajectory().at(t).velocity));
  EXPECT_TRUE(joints_of(values, Field::q_d).isApprox(desired.position));
  EXPECT_TRUE(joints_of(values, Field::dq_d).isApprox(desired.velocity));
  EXPECT_TRUE(joints_of(values, Field::ddq_d).isApprox(desired.acceleration));
  EXPECT_TRUE(pose_of(values, Field::O_T_EE_d)
                  .isApprox(panda::forward_kinematics(desired.position).end_effector.matrix(), 1e-12));
}

TEST(PandaModel, RatesMatchDifferencesOfTheirQuantities) {
  const PandaModel model(3);
  constexpr auto kStep = 10us;
  const double step_seconds = 1e-5;
  for (auto t = 100ms; t < 20s; t += 1700ms) {
    const StateValues now = state_at(model, t);
    const StateValues ahead = state_at(model, t + kStep);
    const StateValues behind = state_at(model, t - kStep);
    const auto difference = [&](Field field) {
      Eigen::VectorXd result(info(field).count);
      for (std::size_t i = 0; i < info(field).count; ++i)
        result[static_cast<Eigen::Index>(i)] =
            (ahead.doubles(field)[i] - behind.doubles(field)[i]) / (2 * step_seconds);
      return result;
    };
    EXPECT_TRUE(joints_of(now, Field::dq).isApprox(difference(Field::q), 1e-6));
    EXPECT_TRUE(joints_of(now, Field::ddq_d).isApprox(difference(Field::dq_d), 1e-6));
    EXPECT_LT((joints_of(now, Field::dtau_J) - difference(Field::tau_J)).cwiseAbs().maxCoeff(), 1e-4);
    EXPECT_LT((joints_of(now, Field::dtheta) - difference(Field::theta)).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_LT((vector6_of(now, Field::O_ddP_EE_c) - difference(Field::O_dP_EE_c)).cwiseAbs().maxCoeff(),
              1e-5);
  }
}

TEST(PandaModel, ElbowFollowsJointsThreeAndFour) {
  const PandaModel model(4);
  const StateValues values = state_at(model, 777ms);
  EXPECT_EQ(values.doubles(Field::elbow)[0], values.doubles(Field::q)[2]);
  EXPECT_EQ(values.doubles(Field::elbow)[1], -1.0);  // joint 4 is always negative on a Panda
  EXPECT_EQ(values.doubles(Field::elbow_d)[0], values.doubles(Field::q_d)[2]);
  EXPECT_EQ(values.doubles(Field::delbow_c)[0], values.doubles(Field::dq_d)[2]);
  EXPECT_EQ(values.doubles(Field::ddelbow_c)[0], values.doubles(Field::ddq_d)[2]);
}

TEST(PandaModel, HealthyRobotMovingFreely) {
  const PandaModel model(5);
  const StateValues values = state_at(model, 2s);
  EXPECT_EQ(values.integer(Field::robot_mode), 2U);  // move
  EXPECT_EQ(values.integer(Field::current_errors), 0U);
  EXPECT_EQ(values.integer(Field::last_motion_errors), 0U);
  EXPECT_EQ(values.doubles(Field::control_command_success_rate)[0], 1.0);
  for (Field field : {Field::joint_contact, Field::cartesian_contact, Field::tau_ext_hat_filtered,
                      Field::O_F_ext_hat_K, Field::K_F_ext_hat_K})
    for (double value : values.doubles(field)) EXPECT_EQ(value, 0.0) << info(field).name;
  EXPECT_GT(values.doubles(Field::m_ee)[0], 0.0);
  EXPECT_EQ(values.doubles(Field::m_total)[0],
            values.doubles(Field::m_ee)[0] + values.doubles(Field::m_load)[0]);
}

TEST(PandaModel, TimeIsWholeMillisecondsSinceStart) {
  const PandaModel model(6);
  EXPECT_EQ(state_at(model, 0ns).integer(Field::time), 0U);
  EXPECT_EQ(state_at(model, 999us).integer(Field::time), 0U);
  EXPECT_EQ(state_at(model, 1ms).integer(Field::time), 1U);
  EXPECT_EQ(state_at(model, 3600s + 20us).integer(Field::time), 3600000U);
}

TEST(PandaModel, WritesOnlyTheSelectedFields) {
  const PandaModel model(7);
  StateValues values;
  for (const FieldInfo& field : kFields)
    if (field.type == ElementType::kFloat64)
      for (double& value : values.doubles(field.id())) value = -12345;
  Selection joints;
  joints.add(Field::q);
  joints.add(Field::dq);
  model.fill(1s, joints, values);
  for (const FieldInfo& field : kFields) {
    if (field.type != ElementType::kFloat64) continue;
    const bool untouched = values.doubles(field.id())[0] == -12345;
    EXPECT_EQ(untouched, !joints.contains(field.id())) << field.name;
  }
}

TEST(PandaModel, EveryStateEncodesToAValidFrame) {
  const PandaModel model(8);
  std::array<std::uint8_t, kMaxFrameBytes> frame{};
  for (auto t = 0ms; t < 60s; t += 997ms) {
    const StateValues values = state_at(model, t);
    const EncodeResult encoded = encode(0, values.selection, values.storage(), StateValues::layout(), frame);
    ASSERT_TRUE(encoded) << encoded.error.message();
    EXPECT_TRUE(decode(std::span(frame).first(encoded.size)));
  }
}

}  // namespace
}  // namespace rsg::sim
