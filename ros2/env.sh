# Source me (bash or zsh): the project-local ROS 2 Jazzy (LTS, Fast DDS 2.14) that `make deps` installs.
#
#   . ros2/env.sh
#   python -c 'import rclpy; from rsg_msgs.msg import RobotState'
#
# wheels     .deps/ros2-jazzy             the Python environment of the ROS 2 Jazzy wheels
#                                         (tools/deps/python/ros2-jazzy.txt): rclpy, rmw_fastrtps_cpp,
#                                         std/sensor/geometry_msgs, rosidl, ament_cmake
# workspace  .deps/ros2_ws-jazzy/install  rsg_msgs (ros2/rsg_msgs) and tf2_msgs (tests/ros2/tf2_msgs)
#                                         built by Jazzy's ament_cmake + rosidl (tools/deps/ros2_ws.sh)
#
# RSG_ROS_DISTRO names the distribution (jazzy, the only one): ROS 2 Kilted, which make deps
# installed beside Jazzy until its end of life (November 2026), was retired (CHANGELOG.md).
#
# The wheels put their libraries in the environment's lib/ and in site-packages/ros_*.libs and
# find packages through the ament index: this sets PATH, LD_LIBRARY_PATH, PYTHONPATH,
# AMENT_PREFIX_PATH, CMAKE_PREFIX_PATH, ROS_DISTRO and RMW_IMPLEMENTATION=rmw_fastrtps_cpp. It also
# tells the wheels' own start-up hook (ros_wheels_bootstrapper, which re-executes Python once to set
# LD_LIBRARY_PATH) that this is done. ROS_DOMAIN_ID is left as it is: use the gateway's --domain.
# Another environment: RSG_DEPS_DIR=/path/to/.deps before sourcing.

if [ -n "${BASH_SOURCE:-}" ]; then
  _rsg_ros2_here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
else
  _rsg_ros2_here=$(cd "$(dirname "$0")" && pwd)  # zsh sets $0 to the sourced file
fi
_rsg_deps=${RSG_DEPS_DIR:-$(dirname "$_rsg_ros2_here")/.deps}
case ${RSG_ROS_DISTRO:-jazzy} in
  jazzy) _rsg_suffix=-jazzy ;;
  kilted)
    echo "ros2/env.sh: ROS 2 Kilted reached its end of life in November 2026 and make deps no longer installs it: use jazzy" >&2
    unset _rsg_ros2_here _rsg_deps
    return 1 2>/dev/null || exit 1
    ;;
  *)
    echo "ros2/env.sh: RSG_ROS_DISTRO=$RSG_ROS_DISTRO: make deps installs jazzy only" >&2
    unset _rsg_ros2_here _rsg_deps
    return 1 2>/dev/null || exit 1
    ;;
esac
export RSG_ROS_DISTRO=${RSG_ROS_DISTRO:-jazzy}
export RSG_ROS2_VENV=$_rsg_deps/ros2$_rsg_suffix
export RSG_ROS2_INSTALL=$_rsg_deps/ros2_ws$_rsg_suffix/install

if [ ! -x "$RSG_ROS2_VENV/bin/python" ] || [ ! -d "$RSG_ROS2_INSTALL/share/rsg_msgs" ]; then
  echo "ros2/env.sh: no ROS 2 $RSG_ROS_DISTRO environment in $_rsg_deps (ros2$_rsg_suffix, ros2_ws$_rsg_suffix/install): run make deps" >&2
  unset _rsg_ros2_here _rsg_deps _rsg_suffix
  return 1 2>/dev/null || exit 1
fi

_rsg_site=$("$RSG_ROS2_VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_path("purelib"))' \
  2>/dev/null || echo "$RSG_ROS2_VENV/lib/python3.11/site-packages")
_rsg_libs=$RSG_ROS2_INSTALL/lib:$RSG_ROS2_VENV/lib
for _rsg_dir in "$_rsg_site"/ros_*.libs; do
  [ -d "$_rsg_dir" ] && _rsg_libs=$_rsg_libs:$_rsg_dir
done

export PATH=$RSG_ROS2_VENV/bin:$PATH
export LD_LIBRARY_PATH=$_rsg_libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export PYTHONPATH=$RSG_ROS2_INSTALL/${_rsg_site#"$RSG_ROS2_VENV"/}${PYTHONPATH:+:$PYTHONPATH}
export AMENT_PREFIX_PATH=$RSG_ROS2_INSTALL:$RSG_ROS2_VENV
export CMAKE_PREFIX_PATH=$RSG_ROS2_INSTALL:$RSG_ROS2_VENV${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}
export RMW_IMPLEMENTATION=rmw_fastrtps_cpp
export ROS_DISTRO=$RSG_ROS_DISTRO ROS_VERSION=2 ROS_PYTHON_VERSION=3
export _ROS_WHEELS_BOOTSTRAP_COMPLETE=1

unset _rsg_ros2_here _rsg_deps _rsg_suffix _rsg_site _rsg_libs _rsg_dir
