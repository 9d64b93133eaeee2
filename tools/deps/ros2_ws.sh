#!/usr/bin/env bash
# The project's ROS 2 workspace: rsg_msgs (ros2/rsg_msgs) and tf2_msgs (tests/ros2/tf2_msgs, no
# wheel of it exists) built by the real ROS 2 pipeline, ROS 2 Jazzy's ament_cmake +
# rosidl_default_generators from its wheels (made by python.sh before this), installed into one prefix:
#   Jazzy   .deps/ros2-jazzy  (tools/deps/python/ros2-jazzy.txt)  -> .deps/ros2_ws-jazzy/install
# ros2/env.sh puts it on the paths. The workspace is built again only when a package's files, its
# wheels' pins or this script changed. (A workspace per distribution: the layout keeps the name of
# the one it was built by, so that another distribution's, should one come, sits beside it.)
set -euo pipefail
cd "$(dirname "$0")/../.."
deps_dir=${DEPS_DIR:-$PWD/.deps}
packages=(ros2/rsg_msgs tests/ros2/tf2_msgs)  # in dependency order

# build_workspace VENV WS REQUIREMENTS
build_workspace() {
  local venv=$1 ws=$2 requirements=$3
  if [[ ! -x $venv/bin/python ]]; then
    echo "make deps: no ROS 2 Python environment in $venv (tools/deps/python.sh makes it)" >&2
    exit 1
  fi
  local stamp
  stamp=$( { cat "$0" "$requirements"; find "${packages[@]}" -type f | LC_ALL=C sort | xargs cat; } \
           | sha256sum | cut -d' ' -f1)
  [[ -f $ws/.rsg-stamp && $(<"$ws/.rsg-stamp") == "$stamp" ]] && return 0

  echo "make deps: ROS 2 workspace $ws/install (${packages[*]##*/})"
  # Built beside the one in use and swapped in at the end, so that tests running meanwhile (another
  # engineer's make test) keep a whole workspace. Installed with DESTDIR: the prefix stays
  # $ws/install, which ament bakes into a few files. A subshell: the exports are this workspace's.
  (
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
        echo "make deps: building $package with ament_cmake/rosidl of $venv failed (whole log: $log)" >&2
        exit 1
      fi
    done
    rm -f "$ws/.rsg-stamp"
    [[ -d $ws/install ]] && mv "$ws/install" "$ws/install.old"
    mv "$stage$ws/install" "$ws/install"
    mv "$build" "$ws/build"
    rm -rf "$ws/install.old" "$stage"
    echo "$stamp" > "$ws/.rsg-stamp"
  )
}

# ROS 2 Kilted's environment and workspace, which make deps made until Kilted's end of life
# (November 2026): removed, so that no test or script finds a retired distribution by accident.
for retired in "$deps_dir/ros2" "$deps_dir/ros2_ws"; do
  if [[ -f $retired/.rsg-stamp ]]; then
    echo "make deps: removing ROS 2 Kilted's $retired (retired)"
    rm -rf "$retired"
  fi
done
build_workspace "$deps_dir/ros2-jazzy" "$deps_dir/ros2_ws-jazzy" tools/deps/python/ros2-jazzy.txt
