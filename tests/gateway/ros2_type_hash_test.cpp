#include "gateway/ros2_type_hash.hpp"

#include <gtest/gtest.h>

#include <string>
#include <string_view>

namespace rsg::gateway {
namespace {

bool is_rihs01(std::string_view hash) {
  constexpr std::string_view kPrefix = "RIHS01_";
  if (!hash.starts_with(kPrefix) || hash.size() != kPrefix.size() + 64) return false;
  return hash.substr(kPrefix.size()).find_first_not_of("0123456789abcdef") == std::string_view::npos;
}

// Every build has them, without ROS 2 at build time (cmake/rsg_ros2_type_hashes.cmake); that they
// are rosidl's own is ros2.type_hashes_match_rosidl's part.
TEST(Ros2TypeHash, EveryRos2TypeTheGatewayPublishesHasARihs01HashByItsDdsAndItsRosName) {
  for (const char* ros_name :
       {"rsg_msgs/msg/RobotState", "rsg_msgs/msg/GatewayStatus", "sensor_msgs/msg/JointState",
        "tf2_msgs/msg/TFMessage", "geometry_msgs/msg/WrenchStamped"}) {
    const std::string name(ros_name);
    const std::size_t msg = name.find("/msg/");
    const std::string dds_name = name.substr(0, msg) + "::msg::dds_::" + name.substr(msg + 5) + "_";
    EXPECT_TRUE(is_rihs01(ros2_type_hash(ros_name))) << ros_name << ": '" << ros2_type_hash(ros_name) << "'";
    EXPECT_EQ(ros2_type_hash(dds_name), ros2_type_hash(ros_name)) << dds_name;
  }
  EXPECT_NE(ros2_type_hash("rsg_msgs/msg/RobotState"), ros2_type_hash("rsg_msgs/msg/GatewayStatus"));
}

TEST(Ros2TypeHash, RsgsOwnDdsTypesHaveNone) {
  EXPECT_EQ(ros2_type_hash("RobotState"), "");
  EXPECT_EQ(ros2_type_hash("GatewayStatus"), "");
}

TEST(Ros2TypeHash, TheAnnouncementIsTheUserDataRmwFastrtpsReads) {
  eprosima::fastdds::dds::UserDataQosPolicy user_data;
  announce_ros2_type_hash(user_data, "rsg_msgs::msg::dds_::RobotState_");
  const std::string text(user_data.data_vec().begin(), user_data.data_vec().end());
  EXPECT_EQ(text, "typehash=" + std::string(ros2_type_hash("rsg_msgs/msg/RobotState")) + ";");

  eprosima::fastdds::dds::UserDataQosPolicy untouched;
  announce_ros2_type_hash(untouched, "RobotState");
  EXPECT_TRUE(untouched.data_vec().empty());
}

}  // namespace
}  // namespace rsg::gateway
