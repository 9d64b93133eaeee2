# RIHS01 type hashes (REP 2011) of the ROS 2 types rsg_gateway publishes (rsg_msgs' RobotState and
# GatewayStatus, sensor_msgs/JointState, tf2_msgs/TFMessage, geometry_msgs/WrenchStamped), for the
# gateway to announce as typehash=RIHS01_...; in its writers' USER_DATA, as rmw_fastrtps does.
# Computed at build time from the .msg files by ros2/type_hashes.py (Python's standard library only,
# no ROS 2 installation) into ${CMAKE_BINARY_DIR}/src/gateway/ros2_type_hashes.hpp (included as
# "gateway/ros2_type_hashes.hpp", from the build tree's mirror of src/): every build
# announces them, the image, a package and the Fast DDS 3 build included. rsg_msgs' members come
# from ros2/rsg_msgs/msg, the standard types' (fixed by ROS 2) from ros2/standard_msgs. rosidl is
# the judge: ros2.type_hashes_match_rosidl compares the header with rosidl's hashes.
find_package(Python3 REQUIRED COMPONENTS Interpreter)
set(RSG_ROS2_TYPE_HASHES_HPP ${CMAKE_BINARY_DIR}/src/gateway/ros2_type_hashes.hpp)
set(_rsg_ros2_types rsg_msgs/msg/RobotState rsg_msgs/msg/GatewayStatus sensor_msgs/msg/JointState
    tf2_msgs/msg/TFMessage geometry_msgs/msg/WrenchStamped)
file(GLOB_RECURSE _rsg_ros2_msgs CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/ros2/rsg_msgs/msg/*.msg
     ${PROJECT_SOURCE_DIR}/ros2/standard_msgs/*.msg)
file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/src/gateway)
add_custom_command(
  OUTPUT ${RSG_ROS2_TYPE_HASHES_HPP}
  COMMAND Python3::Interpreter ${PROJECT_SOURCE_DIR}/ros2/type_hashes.py --header ${RSG_ROS2_TYPE_HASHES_HPP}
          --types ${_rsg_ros2_types} -- ${PROJECT_SOURCE_DIR}/ros2/rsg_msgs ${PROJECT_SOURCE_DIR}/ros2/standard_msgs
  DEPENDS ${PROJECT_SOURCE_DIR}/ros2/type_hashes.py ${_rsg_ros2_msgs}
  COMMENT "RIHS01 type hashes of rsg_msgs and the standard ROS 2 types (REP 2011)")
add_custom_target(rsg_ros2_type_hashes_header DEPENDS ${RSG_ROS2_TYPE_HASHES_HPP})
add_library(rsg_ros2_type_hashes INTERFACE)
add_dependencies(rsg_ros2_type_hashes rsg_ros2_type_hashes_header)
