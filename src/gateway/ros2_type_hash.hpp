// The RIHS01 type hash a ROS 2 node expects in the USER_DATA of rsg's writers and readers of ROS 2
// types: "typehash=RIHS01_<64 hex>;", as rmw_fastrtps (rmw_dds_common) writes it and reads it for
// `ros2 topic info -v` and type checks. Every build computes the hashes from the .msg files
// (cmake/rsg_ros2_type_hashes.cmake, REP 2011), with or without ROS 2; rosidl judges them in a test.
#pragma once

#include <fastdds/dds/core/policy/QosPolicies.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "gateway/ros2_type_hashes.hpp"
#include "rsg/dds/fastdds.hpp"

namespace rsg::gateway {

/// The RIHS01 hash of a ROS 2 type, by its DDS name ("rsg_msgs::msg::dds_::RobotState_") or
/// its ROS name ("rsg_msgs/msg/RobotState"); "" when it is not one of the ROS 2 types the gateway uses.
inline std::string_view ros2_type_hash(std::string_view type_name) {
  constexpr std::string_view kDdsInfix = "::msg::dds_::";  // pkg::msg::dds_::Type_ is pkg/msg/Type
  std::string ros_name(type_name);
  if (const auto dds = ros_name.find(kDdsInfix); dds != std::string::npos && ros_name.ends_with('_')) {
    const std::size_t type_start = dds + kDdsInfix.size();
    ros_name =
        ros_name.substr(0, dds) + "/msg/" + ros_name.substr(type_start, ros_name.size() - 1 - type_start);
  }
  for (const auto& [name, hash] : ros2_generated::kTypeHashes)
    if (name == ros_name) return hash;
  return {};
}

/// Puts "typehash=<hash>;" of `type_name` into `user_data` (replacing what was there) when the hash
/// is known; leaves it alone otherwise.
inline void announce_ros2_type_hash(eprosima::fastdds::dds::UserDataQosPolicy& user_data,
                                    std::string_view type_name) {
  const std::string_view hash = ros2_type_hash(type_name);
  if (hash.empty()) return;
  const std::string text = "typehash=" + std::string(hash) + ";";
  user_data.setValue(std::vector<rsg::dds::rtps::octet>(text.begin(), text.end()));
}

}  // namespace rsg::gateway
