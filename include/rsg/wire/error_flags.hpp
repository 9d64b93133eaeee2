// Names of the values inside `current_errors`, `last_motion_errors` and `robot_mode`.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace rsg::wire {

inline constexpr std::size_t kErrorFlagCount = 37;
/// Bits 37..39 of the 40-bit error set are reserved and make a frame invalid.
inline constexpr std::uint64_t kReservedErrorBits = 0xE0'0000'0000ULL;

inline constexpr std::array<std::string_view, kErrorFlagCount> kErrorFlagNames = {
    "joint_position_limits_violation",
    "cartesian_position_limits_violation",
    "self_collision_avoidance_violation",
    "joint_velocity_violation",
    "cartesian_velocity_violation",
    "force_control_safety_violation",
    "joint_reflex",
    "cartesian_reflex",
    "max_goal_pose_deviation_violation",
    "max_path_pose_deviation_violation",
    "cartesian_velocity_profile_safety_violation",
    "joint_position_motion_generator_start_pose_invalid",
    "joint_motion_generator_position_limits_violation",
    "joint_motion_generator_velocity_limits_violation",
    "joint_motion_generator_velocity_discontinuity",
    "joint_motion_generator_acceleration_discontinuity",
    "cartesian_position_motion_generator_start_pose_invalid",
    "cartesian_motion_generator_elbow_limit_violation",
    "cartesian_motion_generator_velocity_limits_violation",
    "cartesian_motion_generator_velocity_discontinuity",
    "cartesian_motion_generator_acceleration_discontinuity",
    "cartesian_motion_generator_elbow_sign_inconsistent",
    "cartesian_motion_generator_start_elbow_invalid",
    "force_controller_desired_force_tolerance_violation",
    "start_elbow_sign_inconsistent",
    "communication_constraints_violation",
    "power_limit_violation",
    "cartesian_motion_generator_joint_position_limits_violation",
    "cartesian_motion_generator_joint_velocity_limits_violation",
    "cartesian_motion_generator_joint_velocity_discontinuity",
    "cartesian_motion_generator_joint_acceleration_discontinuity",
    "cartesian_position_motion_generator_invalid_frame",
    "controller_torque_discontinuity",
    "joint_p2p_insufficient_torque_for_planning",
    "tau_j_range_violation",
    "instability_detected",
    "joint_move_in_wrong_direction",
};

inline constexpr std::uint8_t kMaxRobotMode = 6;
inline constexpr std::array<std::string_view, kMaxRobotMode + 1> kRobotModeNames = {
    "other", "idle", "move", "guiding", "reflex", "user_stopped", "automatic_error_recovery"};

}  // namespace rsg::wire
