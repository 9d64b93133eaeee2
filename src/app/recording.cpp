#include "app/recording.hpp"

#include <GatewayStatusPubSubTypes.h>
#include <RobotStatePubSubTypes.h>
#include <fastcdr/exceptions/Exception.h>

#include <cstring>

#include "app/recording_schemas.hpp"
#include "dds/internal/fastdds_compat.hpp"

namespace rsg::app {
namespace {

std::span<const std::uint8_t> bytes_of(std::string_view text) {
  return {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()};
}

// What the gateway's writer and status writer offer (xml_profiles/gateway.xml), in the YAML form
// rosbag2 stores per topic (Humble's numeric enums: history 1 keep_last, reliability 1 reliable,
// durability 1 transient_local, liveliness 1 automatic; 9223372036.854775807 s is "infinite").
std::string offered_qos(int depth, bool transient_local, std::uint32_t deadline_ns) {
  const std::string infinite = "    sec: 9223372036\n    nsec: 854775807\n";
  const std::string deadline =
      deadline_ns == 0 ? infinite : "    sec: 0\n    nsec: " + std::to_string(deadline_ns) + "\n";
  return "- history: 1\n  depth: " + std::to_string(depth) +
         "\n  reliability: 1\n  durability: " + (transient_local ? "1" : "2") + "\n  deadline:\n" + deadline +
         "  lifespan:\n" + infinite + "  liveliness: 1\n  liveliness_lease_duration:\n" + infinite +
         "  avoid_ros_namespace_conventions: false";
}

}  // namespace

std::optional<Profile> parse_profile(std::string_view name) {
  if (name.empty() || name == "omgidl") return Profile::omgidl;
  if (name == "ros2") return Profile::ros2;
  return std::nullopt;
}

bool has_ros2_schemas() { return !schemas::kRobotStateMsg.empty(); }
bool has_ros2_status_schema() { return !schemas::kGatewayStatusMsg.empty(); }

std::string_view header_profile(Profile profile) { return profile == Profile::ros2 ? "ros2" : ""; }

bool is_robot_state_schema(std::string_view name) {
  return name == schemas::kRobotStateIdlName || name == schemas::kRobotStateMsgName;
}

Channels add_channels(mcap::Writer& writer, Profile profile, const std::string& state_topic,
                      const std::string& status_topic) {
  Channels channels;
  if (profile == Profile::omgidl) {
    const auto state =
        writer.add_schema(schemas::kRobotStateIdlName, "omgidl", bytes_of(schemas::kRobotStateIdl));
    channels.robot_state = writer.add_channel(state, state_topic, "cdr", {});
    if (!status_topic.empty()) {
      const auto status =
          writer.add_schema(schemas::kGatewayStatusIdlName, "omgidl", bytes_of(schemas::kGatewayStatusIdl));
      channels.status = writer.add_channel(status, status_topic, "cdr", {});
    }
    return channels;
  }
  const auto state =
      writer.add_schema(schemas::kRobotStateMsgName, "ros2msg", bytes_of(schemas::kRobotStateMsg));
  channels.robot_state = writer.add_channel(state, "/" + state_topic, "cdr",
                                            {{"offered_qos_profiles", offered_qos(1000, true, 100'000'000)}});
  if (!status_topic.empty() && !schemas::kGatewayStatusMsg.empty()) {
    const auto status =
        writer.add_schema(schemas::kGatewayStatusMsgName, "ros2msg", bytes_of(schemas::kGatewayStatusMsg));
    channels.status = writer.add_channel(status, "/" + status_topic, "cdr",
                                         {{"offered_qos_profiles", offered_qos(1, true, 0)}});
  }
  return channels;
}

struct CdrSerializer::Types {
  RobotStatePubSubType robot_state;
  GatewayStatusPubSubType status;
  rsg::dds::rtps::SerializedPayload_t payload;
};

CdrSerializer::CdrSerializer() : types_(std::make_unique<Types>()) {
  types_->payload.reserve(std::max(dds::internal::max_serialized_size(types_->robot_state),
                                   dds::internal::max_serialized_size(types_->status)));
  std::memset(types_->payload.data, 0, types_->payload.max_size);
}

// Fast CDR skips the padding before an aligned member without writing it, so a reused buffer would
// carry the previous sample's bytes there: the same sample would not always give the same bytes
// (found comparing a recovered file with another recorder's file of the same stream). Zeroing what
// the previous sample wrote keeps padding 0, as a fresh buffer has it.
void CdrSerializer::clear_payload() {
  std::memset(types_->payload.data, 0, types_->payload.length);
  types_->payload.length = 0;
}

CdrSerializer::~CdrSerializer() = default;

std::span<const std::uint8_t> CdrSerializer::serialize(const RobotState& sample) {
  clear_payload();
  if (!dds::internal::serialize(types_->robot_state, &sample, types_->payload)) return {};
  return {types_->payload.data, types_->payload.length};
}

std::span<const std::uint8_t> CdrSerializer::serialize(const GatewayStatus& sample) {
  clear_payload();
  if (!dds::internal::serialize(types_->status, &sample, types_->payload)) return {};
  return {types_->payload.data, types_->payload.length};
}

bool CdrSerializer::deserialize(std::span<const std::uint8_t> bytes, RobotState& sample) {
  auto& payload = types_->payload;
  if (bytes.size() > payload.max_size) return false;
  clear_payload();
  if (!bytes.empty()) std::memcpy(payload.data, bytes.data(), bytes.size());  // an empty span may be null
  payload.length = static_cast<std::uint32_t>(bytes.size());
  payload.pos = 0;
  try {
    return dds::internal::deserialize(types_->robot_state, payload, &sample);
  } catch (const eprosima::fastcdr::exception::Exception&) {  // e.g. an unknown encapsulation
    return false;
  }
}

}  // namespace rsg::app
