// What rsg_record writes and rsg_replay reads: the MCAP channels of an rsg recording, their
// schemas, and the CDR payload of a sample (the bytes a DDS writer puts on the wire, encapsulation
// header included).
//
// Two flavours (`--profile`): the default describes the messages with rsg's own IDL (`omgidl`,
// what Foxglove decodes); `ros2` follows the MCAP ros2 profile (`ros2msg` schemas of rsg_msgs,
// `/topic` names and the `offered_qos_profiles` rosbag2 expects). The CDR bytes are the same.
#pragma once

#include <GatewayStatus.h>
#include <RobotState.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mcap/mcap_writer.hpp"

namespace rsg::app {

enum class Profile { omgidl, ros2 };

/// "" or "omgidl" -> omgidl, "ros2" -> ros2; nothing for anything else.
std::optional<Profile> parse_profile(std::string_view name);

/// Whether this build embedded rsg_msgs' .msg files (ros2/rsg_msgs/msg/), which --profile ros2 needs.
bool has_ros2_schemas();
/// Whether it embedded ros2/rsg_msgs/msg/GatewayStatus.msg; without it a ros2 recording has no status.
bool has_ros2_status_schema();

/// The MCAP header profile: "" or "ros2".
std::string_view header_profile(Profile profile);

/// Schema names rsg uses for RobotState: "rsg::RobotState" (omgidl), "rsg_msgs/msg/RobotState" (ros2msg).
bool is_robot_state_schema(std::string_view name);

/// The schemas and channels of one recording, registered with a writer.
struct Channels {
  std::uint16_t robot_state = 0;
  std::uint16_t status = 0;  ///< 0 when not recorded
};

/// Adds the schema and channel of `state_topic` (and of `status_topic` unless empty) to `writer`.
/// DDS topic names are kept as they are for omgidl and get a leading '/' for ros2.
Channels add_channels(mcap::Writer& writer, Profile profile, const std::string& state_topic,
                      const std::string& status_topic);

/// Serializes samples as a Fast DDS writer does (CDR with its encapsulation header), reusing one buffer.
class CdrSerializer {
 public:
  CdrSerializer();
  ~CdrSerializer();
  CdrSerializer(const CdrSerializer&) = delete;
  CdrSerializer& operator=(const CdrSerializer&) = delete;

  std::span<const std::uint8_t> serialize(const RobotState& sample);
  std::span<const std::uint8_t> serialize(const GatewayStatus& sample);
  /// False when `bytes` is no valid RobotState CDR payload.
  bool deserialize(std::span<const std::uint8_t> bytes, RobotState& sample);

 private:
  void clear_payload();

  struct Types;
  std::unique_ptr<Types> types_;
};

}  // namespace rsg::app
