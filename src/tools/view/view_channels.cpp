#include "tools/view/view_channels.hpp"

#include <nlohmann/json.hpp>

#include "app/recording_schemas.hpp"
#include "rsg/dds/robot_state.hpp"
#include "rsg/wire/eigen.hpp"
#include "rsg/wire/error_flags.hpp"
#include "status/status_sample.hpp"

namespace rsg::tools::view {
namespace {

using nlohmann::json;
namespace schemas = rsg::app::schemas;

// JSON Schemas of the JSON channels: Foxglove wants one per channel; these say the shape.
constexpr std::string_view kFrameTransformSchema = R"({"type":"object","properties":{
"timestamp":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}},
"parent_frame_id":{"type":"string"},"child_frame_id":{"type":"string"},
"translation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}},
"rotation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}}}})";
constexpr std::string_view kObjectSchema = R"({"type":"object"})";

json error_names(std::uint64_t bits) {
  json names = json::array();
  for (std::size_t i = 0; i < wire::kErrorFlagCount; ++i)
    if ((bits >> i) & 1U) names.push_back(wire::kErrorFlagNames[i]);
  return names;
}

template <typename T>
json or_null(const std::optional<T>& value) {
  return value ? json(*value) : json(nullptr);
}

}  // namespace

ChannelSet::ChannelSet(const std::string& state_topic, const std::string& status_topic) {
  channels_.push_back({kStateIdl, state_topic, "cdr", std::string(schemas::kRobotStateIdlName),
                       std::string(schemas::kRobotStateIdl), "omgidl"});
  robot_state_cdr_.push_back(kStateIdl);
  if (!schemas::kRobotStateMsg.empty()) {
    channels_.push_back({kStateMsg, "/" + state_topic, "cdr", std::string(schemas::kRobotStateMsgName),
                         std::string(schemas::kRobotStateMsg), "ros2msg"});
    robot_state_cdr_.push_back(kStateMsg);
  }
  channels_.push_back({kTransform, state_topic + "/ee_transform", "json", "foxglove.FrameTransform",
                       std::string(kFrameTransformSchema), "jsonschema"});
  channels_.push_back(
      {kSummary, state_topic + "/page", "json", "rsg.PageSummary", std::string(kObjectSchema), "jsonschema"});
  if (!status_topic.empty()) {
    channels_.push_back({kStatusCdr, status_topic, "cdr", std::string(schemas::kGatewayStatusIdlName),
                         std::string(schemas::kGatewayStatusIdl), "omgidl"});
    status_cdr_.push_back(kStatusCdr);
    if (!schemas::kGatewayStatusMsg.empty()) {
      channels_.push_back({kStatusMsg, "/" + status_topic, "cdr", std::string(schemas::kGatewayStatusMsgName),
                           std::string(schemas::kGatewayStatusMsg), "ros2msg"});
      status_cdr_.push_back(kStatusMsg);
    }
    channels_.push_back({kStatusJson, status_topic + "/json", "json", "rsg.GatewayStatus",
                         std::string(kObjectSchema), "jsonschema"});
  }
}

std::optional<std::string> frame_transform_json(const RobotState& sample, std::uint64_t time_ns) {
  if (!dds::selection_of(sample).contains(wire::Field::O_T_EE)) return std::nullopt;
  const Eigen::Isometry3d pose = wire::eigen::isometry(sample.O_T_EE());
  const Eigen::Vector3d t = pose.translation();
  // A frame from a real controller holds a rotation; normalizing keeps Foxglove's 3D panel sane otherwise.
  const Eigen::Quaterniond r = Eigen::Quaterniond(pose.linear()).normalized();
  const json out{{"timestamp", {{"sec", time_ns / 1'000'000'000U}, {"nsec", time_ns % 1'000'000'000U}}},
                 {"parent_frame_id", "base"},
                 {"child_frame_id", "end_effector"},
                 {"translation", {{"x", t.x()}, {"y", t.y()}, {"z", t.z()}}},
                 {"rotation", {{"x", r.x()}, {"y", r.y()}, {"z", r.z()}, {"w", r.w()}}}};
  return out.dump();
}

std::string status_json(const GatewayStatus& sample) {
  return status::to_json(status::from_status_sample(sample));
}

void PageSummary::add(const RobotState& sample) {
  ++samples_;
  const wire::Selection selection = dds::selection_of(sample);
  if (selection.contains(wire::Field::time)) time_ = sample.time();
  if (selection.contains(wire::Field::robot_mode)) robot_mode_ = sample.robot_mode();
  if (selection.contains(wire::Field::q)) q_ = sample.q();
  if (selection.contains(wire::Field::dq)) dq_ = sample.dq();
  if (selection.contains(wire::Field::tau_J)) tau_J_ = sample.tau_J();
  if (selection.contains(wire::Field::O_T_EE)) {
    const Eigen::Vector3d t = wire::eigen::pose(sample.O_T_EE()).block<3, 1>(0, 3);
    ee_position_ = std::array<double, 3>{t.x(), t.y(), t.z()};
  }
  if (selection.contains(wire::Field::control_command_success_rate))
    success_rate_ = sample.control_command_success_rate();
  if (selection.contains(wire::Field::current_errors)) current_errors_ = sample.current_errors();
  if (selection.contains(wire::Field::last_motion_errors)) last_motion_errors_ = sample.last_motion_errors();
}

std::string PageSummary::json(std::uint64_t dropped) const {
  nlohmann::json out{
      {"samples", samples_},
      {"time", or_null(time_)},
      {"robot_mode", or_null(robot_mode_)},
      {"robot_mode_name", nullptr},
      {"q", or_null(q_)},
      {"dq", or_null(dq_)},
      {"tau_J", or_null(tau_J_)},
      {"ee_position", or_null(ee_position_)},
      {"success_rate", or_null(success_rate_)},
      {"current_errors", current_errors_ ? error_names(*current_errors_) : nlohmann::json(nullptr)},
      {"last_motion_errors",
       last_motion_errors_ ? error_names(*last_motion_errors_) : nlohmann::json(nullptr)},
      {"dropped", dropped}};
  if (robot_mode_ && *robot_mode_ <= wire::kMaxRobotMode)
    out["robot_mode_name"] = wire::kRobotModeNames[*robot_mode_];
  return out.dump();
}

}  // namespace rsg::tools::view
