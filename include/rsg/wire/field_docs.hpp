// What each field of the table means and in which unit, as docs/protocol.md states it. For tools that
// show fields to people (the Wireshark dissector); decoding never needs it.
//
// A switch over `Field` rather than a second list: with -Wswitch -Werror a field added to the table
// without its entry here does not compile.
#pragma once

#include <string_view>

#include "rsg/wire/field_table.hpp"

namespace rsg::wire {

struct FieldDoc {
  /// One unit for every element, or one per element separated by commas ("N,N,N,Nm,Nm,Nm").
  /// Empty for unitless values, error sets and `robot_mode`.
  std::string_view unit;
  std::string_view meaning;
  /// Number of rows when the field is a column-major matrix (4 for a pose, 3 for an inertia), else 0.
  unsigned matrix_rows = 0;
};

constexpr FieldDoc field_doc(Field field) {
  constexpr std::string_view kWrench = "N,N,N,Nm,Nm,Nm";
  constexpr std::string_view kTwist = "m/s,m/s,m/s,rad/s,rad/s,rad/s";
  switch (field) {
    case Field::O_T_EE:
      return {"", "measured end-effector pose in base frame O", 4};
    case Field::O_T_EE_d:
      return {"", "last desired end-effector pose of the motion generator", 4};
    case Field::F_T_EE:
      return {"", "end-effector pose in the flange frame", 4};
    case Field::EE_T_K:
      return {"", "stiffness frame K relative to the end effector", 4};
    case Field::m_ee:
      return {"kg", "configured end-effector mass"};
    case Field::I_ee:
      return {"kg m^2", "end-effector inertia about its centre of mass", 3};
    case Field::F_x_Cee:
      return {"m", "end-effector centre of mass in the flange frame"};
    case Field::m_load:
      return {"kg", "external load mass"};
    case Field::I_load:
      return {"kg m^2", "load inertia", 3};
    case Field::F_x_Cload:
      return {"m", "load centre of mass in the flange frame"};
    case Field::m_total:
      return {"kg", "end effector plus load mass"};
    case Field::I_total:
      return {"kg m^2", "combined inertia", 3};
    case Field::F_x_Ctotal:
      return {"m", "combined centre of mass"};
    case Field::elbow:
      return {"rad,sign", "elbow: joint-3 position, joint-4 flip sign"};
    case Field::elbow_d:
      return {"rad,sign", "desired elbow"};
    case Field::elbow_c:
      return {"rad,sign", "commanded elbow"};
    case Field::delbow_c:
      return {"rad/s,", "commanded elbow velocity"};
    case Field::ddelbow_c:
      return {"rad/s^2,", "commanded elbow acceleration"};
    case Field::tau_J:
      return {"Nm", "measured link-side joint torque"};
    case Field::tau_J_d:
      return {"Nm", "desired link-side torque without gravity"};
    case Field::dtau_J:
      return {"Nm/s", "derivative of tau_J"};
    case Field::q:
      return {"rad", "measured joint position"};
    case Field::q_d:
      return {"rad", "desired joint position"};
    case Field::dq:
      return {"rad/s", "measured joint velocity"};
    case Field::dq_d:
      return {"rad/s", "desired joint velocity"};
    case Field::ddq_d:
      return {"rad/s^2", "desired joint acceleration"};
    case Field::joint_contact:
      return {"", "contact level per joint"};
    case Field::cartesian_contact:
      return {"", "contact level per axis x, y, z, roll, pitch, yaw"};
    case Field::joint_collision:
      return {"", "collision level per joint (latched)"};
    case Field::cartesian_collision:
      return {"", "collision level per axis (latched)"};
    case Field::tau_ext_hat_filtered:
      return {"Nm", "filtered external joint torque"};
    case Field::O_F_ext_hat_K:
      return {kWrench, "external wrench on K in frame O"};
    case Field::K_F_ext_hat_K:
      return {kWrench, "external wrench on K in frame K"};
    case Field::O_dP_EE_d:
      return {kTwist, "desired end-effector twist in O"};
    case Field::O_T_EE_c:
      return {"", "last commanded end-effector pose", 4};
    case Field::O_dP_EE_c:
      return {kTwist, "last commanded end-effector twist"};
    case Field::O_ddP_EE_c:
      return {"m/s^2,m/s^2,m/s^2,rad/s^2,rad/s^2,rad/s^2", "last commanded end-effector acceleration"};
    case Field::theta:
      return {"rad", "motor position"};
    case Field::dtheta:
      return {"rad/s", "motor velocity"};
    case Field::current_errors:
      return {"", "error flags active now"};
    case Field::last_motion_errors:
      return {"", "error flags that stopped the last motion"};
    case Field::control_command_success_rate:
      return {"", "share of the last 100 control commands received, 0..1"};
    case Field::robot_mode:
      return {"", "robot mode"};
    case Field::time:
      return {"ms", "time since robot start"};
  }
  return {};
}

}  // namespace rsg::wire
