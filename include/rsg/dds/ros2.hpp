// ROS 2 naming on plain DDS: what makes a ROS 2 node see an rsg topic with no bridge.
//
// ROS 2 (every rmw on DDS) prefixes topic names with "rt" and names the DDS type of
// `<pkg>/msg/<Type>` `<pkg>::msg::dds_::<Type>_`; rsg_msgs (ros2/rsg_msgs) describes the same bytes
// as rsg's IDL types, so the gateway only registers its types under these names. Header-only and
// free of DDS, so that the configuration parser (fuzzed without DDS) can check namespaces.
#pragma once

#include <string>
#include <string_view>

#include "rsg/wire/parsed.hpp"

namespace rsg::dds {

inline constexpr std::string_view kRos2RobotStateType = "rsg_msgs::msg::dds_::RobotState_";
inline constexpr std::string_view kRos2GatewayStatusType = "rsg_msgs::msg::dds_::GatewayStatus_";

/// Checks a ROS 2 namespace ("" is the root; "/robot1" or "robot1", "/a/b").
/// @return the namespace as given, or what is wrong with it.
inline wire::Parsed<std::string> parse_ros2_namespace(std::string_view ns) {
  // ROS 2 name rules (a subset is enough here): tokens of [A-Za-z0-9_] not starting with a digit,
  // separated by single '/'.
  const std::string_view body = ns.starts_with('/') ? ns.substr(1) : ns;
  if (body.empty()) {
    if (ns.empty() || ns == "/") return std::string(ns);
    return wire::ParseFailure{"is not a ROS 2 namespace"};
  }
  bool token_start = true;
  for (char c : body) {
    if (c == '/') {
      if (token_start) return wire::ParseFailure{"'" + std::string(ns) + "' has an empty name between '/'"};
      token_start = true;
      continue;
    }
    const bool word = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    if (!word)
      return wire::ParseFailure{"'" + std::string(ns) + "': only letters, digits, '_' and '/' are allowed"};
    if (token_start && c >= '0' && c <= '9')
      return wire::ParseFailure{"'" + std::string(ns) + "': a name must not start with a digit"};
    token_start = false;
  }
  if (token_start) return wire::ParseFailure{"'" + std::string(ns) + "' must not end with '/'"};
  return std::string(ns);
}

/// The DDS topic of ROS 2 topic `name` in namespace `ns`: ("/robot1", "joint_states") ->
/// "rt/robot1/joint_states"; a name starting with '/' is absolute ("/tf" -> "rt/tf").
/// Assumes a valid namespace.
inline std::string ros2_topic_name(std::string_view ns, std::string_view name) {
  std::string topic = "rt";
  if (!name.starts_with('/')) {
    if (!ns.empty() && ns != "/" && !ns.starts_with('/')) topic += '/';
    if (ns != "/") topic += ns;
    topic += '/';
  }
  topic += name;
  return topic;
}

}  // namespace rsg::dds
