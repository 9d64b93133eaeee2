#!/usr/bin/env bash
# make test-fastdds214: rsg against Fast DDS 2.14.5 (ROS 2 Jazzy's LTS, from its PyPI wheels), found
# the way a shell that sourced Jazzy finds it: on CMAKE_PREFIX_PATH, no switch. And 2.9 <-> 2.14 on
# one domain, both ways, with the Debian 12 (2.9.1) build of the host. docs/fastdds-versions.md.
#
#   tests/fastdds214/run.sh [HOST_BUILD]     HOST_BUILD: the host's 2.9 build tree (default build)
#
# 1. installs the wheels (tests/fastdds214/requirements.txt, pinned with hashes) into
#    $DEPS_DIR/fastdds214 (or $RSG_FASTDDS214_PREFIX), once per requirements file;
# 2. configures and builds $RSG_FASTDDS214_BUILD (default build-fdds214) with that environment first
#    on CMAKE_PREFIX_PATH and LD_LIBRARY_PATH, as Jazzy's setup.bash puts it: the targets of the
#    tests below only;
# 3. runs there the unit tests of the folders that use Fast DDS, the views (content filters included), the pipeline, the embedded
#    gateway, the installed package's consumers, and the gateway inside a ROS 2 Jazzy node
#    (examples/ros2_node, built in make deps' Jazzy environment: tests/ros2/test_ros2_node.py);
# 4. compares rsg_type_dump of both builds (sample bytes, largest sizes, TypeObject identifiers),
#    then runs views and the pipeline with the processes of one side from each build.
# Closes with its time and one line "test-fastdds214: N passed, N failed".
set -uo pipefail
cd "$(dirname "$0")/../.."
# The Python tests import tests/support's helpers by name: that folder on PYTHONPATH, as ctest's
# tests/support/python.py puts it.
export PYTHONPATH=$PWD/tests/support${PYTHONPATH:+:$PYTHONPATH}
checkout=$PWD
host_build=${1:-build}
build=${RSG_FASTDDS214_BUILD:-build-fdds214}
deps=${DEPS_DIR:-$checkout/.deps}
venv=${RSG_FASTDDS214_PREFIX:-$deps/fastdds214}  # where the wheels go
requirements=tests/fastdds214/requirements.txt
jobs=${JOBS:-$(nproc)}
logs=$build/test-fastdds214
integration="sim_to_echo|invalid_frames|sequence_and_link|raw_roundtrip|selection_request|startup_errors"
integration+="|late_joiner|rate_topic|realtime_gateway|embedded_controller|dds_attacks|reader_teardown"
# The published Fast DDS flaws, with their controls (what each does to a plain 2.14.5 participant).
integration+="|fastdds_flaws"
processes="views\.rsg_echo|integration\.($integration)|gateway\.embedded|cli\.rsg_frame|packaging\.install_consumer"
processes+="|ros2\.(standard_topics|msg_matches_field_table)"
# unit_tests_dds: the unit tests of the folders that use Fast DDS (those of wire, transport, capture,
# mcap, foxglove and the simulator run in make test; no Fast DDS version changes them).
targets=(unit_tests_dds rsg_gateway rsg_sim rsg_echo rsg_frame rsg_status_probe rsg_views_publish rsg_view
         rsg_example_embedded_controller rsg_ros2_standard_echo rsg_generate_msg rsg_record rsg_replay
         rsg_embedded_gateway rsg_type_dump rsg_reader_teardown_probe rsg_fastdds_flaws_probe)

suite=fastdds214
source tests/support/suite_counts.sh

start=$SECONDS
# 1. The wheels: Debian's Python 3.11, which they are built for (cp311).
stamp=$(sha256sum "$requirements" | cut -d' ' -f1)
if [[ ! -f $venv/.rsg-stamp || $(<"$venv/.rsg-stamp") != "$stamp" ]]; then
  echo "test-fastdds214: Fast DDS 2.14.5 wheels into $venv"
  rm -rf "$venv"
  /usr/bin/python3 -m venv "$venv" || exit 1
  "$venv/bin/pip" install --quiet --disable-pip-version-check --no-input --require-hashes \
    --only-binary=:all: -r "$requirements" || exit 1
  echo "$stamp" > "$venv/.rsg-stamp"
fi
# 2. What sourcing Jazzy sets: its prefix first on CMAKE_PREFIX_PATH, its libraries (the wheel's own
# OpenSSL and TinyXML-2 among them) on LD_LIBRARY_PATH. The 2.9 programs of the cross tests need
# none of these libraries' names (libfastrtps.so.2.14, libfastcdr.so.2, hashed names of the rest).
export CMAKE_PREFIX_PATH=$venv${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}
bundled=$(echo "$venv"/lib/python3*/site-packages/ros_fastrtps.libs)
export LD_LIBRARY_PATH=$venv/lib:$bundled${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
generator=()
[[ -f $build/CMakeCache.txt ]] || generator=(-G Ninja)
mkdir -p "$build"
cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG" "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG" \
  -DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DRSG_DEPS_DIR="$deps" \
  > "$build/configure.log" 2>&1 || { cat "$build/configure.log"; exit 1; }
grep -E '^-- rsg: ' "$build/configure.log"
grep -q '^-- rsg: Fast DDS 2\.14\.' "$build/configure.log" || { echo "test-fastdds214: CMake did not find Fast DDS 2.14" >&2; exit 1; }
cmake --build "$build" -j "$jobs" --target "${targets[@]}" > "$build/build.log" 2>&1 || {
  grep -E 'error|FAILED' -A5 "$build/build.log" | head -n 60; exit 1; }
mkdir -p "$logs"
echo "test-fastdds214: built in $((SECONDS - start)) s"

# 3. On 2.14 alone: the unit tests built (unit_tests_dds) but packaging (it checks Debian 12's package lists);
# packaging.install_consumer runs with the process tests.
(cd "$build" && ctest --output-on-failure -j "$((jobs + 1))" -L unit -E '^packaging') > "$logs/unit.log" 2>&1
tail -n 3 "$logs/unit.log"
count_ctest "$logs/unit.log"
# packaging.install_consumer builds its three consumers in a scratch directory with plain CMake, most
# of this suite's time: through ccache, with paths taken relative (the scratch name changes every run).
(cd "$build" && CMAKE_C_COMPILER_LAUNCHER=ccache CMAKE_CXX_COMPILER_LAUNCHER=ccache CCACHE_BASEDIR=/ \
   ctest --output-on-failure -j "$((jobs + 1))" -R "^($processes)\$") > "$logs/processes.log" 2>&1
grep -E '^ *[0-9]+/[0-9]+ Test|tests passed' "$logs/processes.log"
count_ctest "$logs/processes.log"

# The gateway inside a ROS 2 Jazzy node (examples/ros2_node): rsg installed from this build, the
# example built in make deps' Jazzy environment against it, one Fast DDS in the process, read by a
# Jazzy rclpy subscription.
check ros2_node_jazzy python3 tests/ros2/test_ros2_node.py --bin "$build/bin"

# 4. Against 2.9.
if [[ ! -x $host_build/tests/bin/rsg_type_dump || ! -x $host_build/tests/bin/rsg_views_publish ]]; then
  echo "test-fastdds214: no host build in $host_build (make build): 2.9 <-> 2.14 not run" >&2
  failed=$((failed + 1))
else
  # The type support: the same bytes for the same sample, the same largest sizes, the same type
  # identifiers (TypeInformation) as fastddsgen 2.3's on 2.9.
  check type_support_matches_2.9 diff <("$host_build/tests/bin/rsg_type_dump") <("$build/tests/bin/rsg_type_dump")
  # Bin directories with each executable from one version: the 2.9 build's (bin/ and tests/bin/:
  # CONTRIBUTING.md, "Build tree"), some replaced by 2.14's.
  mixed() {  # NAME TOOLS_FROM_2.14...
    local dir=$logs/bin-$1 tool path; shift
    rm -rf "$dir" && mkdir -p "$dir"
    for tool in "$checkout/$host_build"/bin/* "$checkout/$host_build"/tests/bin/*; do ln -s "$tool" "$dir/"; done
    for tool in "$@"; do
      path=$checkout/$build/bin/$tool
      [[ -e $path ]] || path=$checkout/$build/tests/bin/$tool
      ln -sfn "$path" "$dir/$tool"
    done
    echo "$dir"
  }
  gateway214=$(mixed gateway214 rsg_gateway)
  echo214=$(mixed echo214 rsg_echo rsg_status_probe)
  publish214=$(mixed publish214 rsg_views_publish)
  # Views, content filters included: 2.14 readers on a 2.9 writer's stream, and 2.9 readers on 2.14's.
  check views_2.9_writer_2.14_readers env RSG_SIM="$host_build/bin/rsg_sim" RSG_GATEWAY="$host_build/bin/rsg_gateway" \
    python3 tests/dds/echo_views_test.py --echo "$echo214/rsg_echo" \
    --publish "$host_build/tests/bin/rsg_views_publish" -v
  check views_2.14_writer_2.9_readers env RSG_SIM="$host_build/bin/rsg_sim" RSG_GATEWAY="$host_build/bin/rsg_gateway" \
    python3 tests/dds/echo_views_test.py --echo "$host_build/bin/rsg_echo" \
    --publish "$publish214/rsg_views_publish" -v
  # The pipeline: a 2.14 gateway read by 2.9's rsg_echo (and status probe), a 2.9 gateway read by 2.14's.
  check sim_to_echo_2.14_gateway_2.9_echo python3 tests/integration/test_sim_to_echo.py --bin "$gateway214"
  check sim_to_echo_2.9_gateway_2.14_echo python3 tests/integration/test_sim_to_echo.py --bin "$echo214"
fi
echo "test-fastdds214: $((SECONDS - start)) s"
echo "test-fastdds214: $passed passed, $failed failed"
[[ $failed == 0 ]]
