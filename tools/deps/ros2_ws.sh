#!/usr/bin/env bash
# The project's ROS 2 workspace: rsg_msgs (ros2/rsg_msgs) and tf2_msgs (tests/ros2/tf2_msgs, no
# wheel of it exists) built by the real ROS 2 pipeline, ament_cmake + rosidl_default_generators of
# the Kilted wheels in $DEPS_DIR/ros2 (tools/deps/python/ros2.txt, made by python.sh before this),
# installed into one prefix, $DEPS_DIR/ros2_ws/install. ros2/env.sh puts it on the paths. Built again
# only when a package's files, the wheels' pins or this script changed.
set -euo pipefail
cd "$(dirname "$0")/../.."
deps_dir=${DEPS_DIR:-$PWD/.deps}
venv=$deps_dir/ros2
ws=$deps_dir/ros2_ws
packages=(ros2/rsg_msgs tests/ros2/tf2_msgs)  # in dependency order

if [[ ! -x $venv/bin/python ]]; then
  echo "make deps: no ROS 2 Python environment in $venv (tools/deps/python.sh makes it)" >&2
  exit 1
fi
stamp=$( { cat "$0" tools/deps/python/ros2.txt; find "${packages[@]}" -type f | LC_ALL=C sort | xargs cat; } \
         | sha256sum | cut -d' ' -f1)
[[ -f $ws/.rsg-stamp && $(<"$ws/.rsg-stamp") == "$stamp" ]] && exit 0

echo "make deps: ROS 2 workspace $ws/install (${packages[*]##*/})"
rm -rf "$ws"
mkdir -p "$ws"
site=$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_path("purelib"))')
libs=$venv/lib
for dir in "$site"/ros_*.libs; do libs=$libs:$dir; done
export AMENT_PREFIX_PATH=$ws/install:$venv CMAKE_PREFIX_PATH=$ws/install:$venv
export PATH=$venv/bin:$PATH LD_LIBRARY_PATH=$ws/install/lib:$libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export _ROS_WHEELS_BOOTSTRAP_COMPLETE=1
generator=()
command -v ninja > /dev/null && generator=(-G Ninja)
for package in "${packages[@]}"; do
  name=${package##*/}
  log=$ws/build/$name.log
  mkdir -p "$ws/build"
  if ! { cmake -S "$package" -B "$ws/build/$name" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
           -DCMAKE_INSTALL_PREFIX="$ws/install" -DBUILD_TESTING=OFF -DPython3_EXECUTABLE="$venv/bin/python3" \
         && cmake --build "$ws/build/$name" -j2 && cmake --install "$ws/build/$name"; } > "$log" 2>&1; then
    tail -n 40 "$log" >&2
    echo "make deps: building $package with ament_cmake/rosidl failed (whole log: $log)" >&2
    exit 1
  fi
done
echo "$stamp" > "$ws/.rsg-stamp"
