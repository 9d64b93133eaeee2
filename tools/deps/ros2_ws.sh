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
# Built beside the one in use and swapped in at the end, so that tests running meanwhile (another
# engineer's make test) keep a whole workspace. Installed with DESTDIR: the prefix stays $ws/install,
# which ament bakes into a few files.
build=$ws/build.new
stage=$ws/stage
rm -rf "$build" "$stage" "$ws/build"
mkdir -p "$build"
site=$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_path("purelib"))')
libs=$venv/lib
for dir in "$site"/ros_*.libs; do libs=$libs:$dir; done
# The ament index keeps AMENT_PREFIX_PATH as the packages' parent prefixes: the final one, not the stage.
export AMENT_PREFIX_PATH=$ws/install:$venv CMAKE_PREFIX_PATH=$stage$ws/install:$venv
export PATH=$venv/bin:$PATH LD_LIBRARY_PATH=$stage$ws/install/lib:$libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export _ROS_WHEELS_BOOTSTRAP_COMPLETE=1
generator=()
command -v ninja > /dev/null && generator=(-G Ninja)
for package in "${packages[@]}"; do
  name=${package##*/}
  log=$build/$name.log
  if ! { cmake -S "$package" -B "$build/$name" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
           -DCMAKE_INSTALL_PREFIX="$ws/install" -DBUILD_TESTING=OFF -DPython3_EXECUTABLE="$venv/bin/python3" \
         && cmake --build "$build/$name" -j2 && DESTDIR=$stage cmake --install "$build/$name"; } > "$log" 2>&1; then
    tail -n 40 "$log" >&2
    echo "make deps: building $package with ament_cmake/rosidl failed (whole log: $log)" >&2
    exit 1
  fi
done
rm -f "$ws/.rsg-stamp"
[[ -d $ws/install ]] && mv "$ws/install" "$ws/install.old"
mv "$stage$ws/install" "$ws/install"
mv "$build" "$ws/build"
rm -rf "$ws/install.old" "$stage"
echo "$stamp" > "$ws/.rsg-stamp"
