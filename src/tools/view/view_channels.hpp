// What rsg_view offers a Foxglove client: its channels (ids, topics, schemas) and the JSON
// messages it derives from the DDS samples (the end-effector transform, the page's summary, the
// gateway status). The CDR channels carry the samples' own bytes.
#pragma once

#include <GatewayStatus.h>
#include <RobotState.h>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "foxglove/foxglove_protocol.hpp"

namespace rsg::tools::view {

class ChannelSet {
 public:
  /// RobotState as cdr + omgidl and (when this build has rsg_msgs' .msg) cdr + ros2msg on
  /// "/<state_topic>"; unless `status_topic` is empty, GatewayStatus the same two ways (the ros2msg
  /// one on "/<status_topic>") and as JSON; "<state_topic>/ee_transform" (foxglove.FrameTransform);
  /// "<state_topic>/page" (the page's summary).
  ChannelSet(const std::string& state_topic, const std::string& status_topic);

  const std::vector<foxglove::Channel>& channels() const { return channels_; }
  /// The channels that carry a RobotState's CDR bytes (the same bytes for both schemas).
  const std::vector<std::uint32_t>& robot_state_cdr() const { return robot_state_cdr_; }
  /// The channels that carry a GatewayStatus's CDR bytes.
  const std::vector<std::uint32_t>& status_cdr() const { return status_cdr_; }
  std::uint32_t status_json() const { return kStatusJson; }
  std::uint32_t transform() const { return kTransform; }
  std::uint32_t summary() const { return kSummary; }

 private:
  static constexpr std::uint32_t kStateIdl = 1, kStateMsg = 2, kStatusCdr = 3, kTransform = 4, kSummary = 5,
                                 kStatusJson = 6, kStatusMsg = 7;
  std::vector<foxglove::Channel> channels_;
  std::vector<std::uint32_t> robot_state_cdr_, status_cdr_;
};

/// foxglove.FrameTransform "base" -> "end_effector" from O_T_EE; nothing when the sample lacks O_T_EE.
std::optional<std::string> frame_transform_json(const RobotState& sample, std::uint64_t time_ns);

/// The gateway status with the counter names of GatewayStatus.idl (the gateway's --stats-file form).
std::string status_json(const GatewayStatus& sample);

/// The latest value of each field the page shows. Samples carry only their selected fields (and a
/// view only some groups), so each field keeps its last value until a sample carries it again.
class PageSummary {
 public:
  void add(const RobotState& sample);
  /// {"samples", "time", "robot_mode", "robot_mode_name", "q", "dq", "tau_J", "ee_position",
  ///  "success_rate", "current_errors", "last_motion_errors", "dropped"}; absent fields are null.
  std::string json(std::uint64_t dropped) const;
  std::uint64_t samples() const { return samples_; }

 private:
  std::uint64_t samples_ = 0;
  std::optional<std::uint64_t> time_;
  std::optional<std::uint8_t> robot_mode_;
  std::optional<std::array<double, 7>> q_, dq_, tau_J_;
  std::optional<std::array<double, 3>> ee_position_;
  std::optional<double> success_rate_;
  std::optional<std::uint64_t> current_errors_, last_motion_errors_;
};

}  // namespace rsg::tools::view
