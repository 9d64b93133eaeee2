#!/usr/bin/env bash
# make test-fastdds3: rsg against Fast DDS 3.6 (ROS 2 Lyrical's line: Debian experimental's 3.6.1,
# Fast CDR 2.3, fastddsgen 4.3, on Debian 13) in the chroot of tools/fastdds3/chroot.sh, and across
# versions with the Debian 12 (2.9.1) build of the host and the Fast DDS 2.14 (ROS 2 Jazzy) build of
# make test-fastdds214. Which tests run where: docs/fastdds-versions.md.
#
#   tests/fastdds3/run.sh [HOST_BUILD]     HOST_BUILD: the host's 2.9 build tree (default build)
#   RSG_FASTDDS214_BUILD                   the 2.14 tree (default build-fdds214: make test-fastdds214
#                                          builds it; the 2.14 <-> 3.6 tests fail without it)
#
# 1. builds the checkout in the chroot into $RSG_FASTDDS3_BUILD (default build-fdds3), the targets
#    of the chosen tests only;
# 2. runs there the unit tests of the folders that use Fast DDS (unit_tests_dds), the views, the
#    Cyclone interop and the integration subset below;
# 3. runs on the host the cross-version tests: the same test scripts with the processes of one side
#    from the 2.9 (or 2.14) build and of the other from the 3.x build (run in the chroot), on one DDS
#    domain, both ways: the chroot shares the host's network and /dev/shm.
# Closes with one line "test-fastdds3: N passed, N failed".
set -uo pipefail
cd "$(dirname "$0")/../.."
# The Python tests import tests/support's helpers by name: that folder on PYTHONPATH, as ctest's
# tests/support/python.py puts it.
export PYTHONPATH=$PWD/tests/support${PYTHONPATH:+:$PYTHONPATH}
checkout=$PWD
host_build=${1:-build}
build214=${RSG_FASTDDS214_BUILD:-build-fdds214}
build=${RSG_FASTDDS3_BUILD:-build-fdds3}
jobs=${JOBS:-$(nproc)}
chroot=tools/fastdds3/chroot.sh
logs=$build/test-fastdds3
# The process tests that also run against 3.x: the pipeline, its errors and selections, a
# data-sharing reader's history (late_joiner), rate topics, the demo, the embedded gateway, the
# Fast DDS attacks, the
# standard ROS 2 topics read by Cyclone, the CLI. Not the ones that need tshark or Node (pcap_replay,
# replay_formats, flight_recorder; record.*, view.*), nor Debian's rosidl (ros2.rosidl_cyclone,
# ros2.egress: run across below): the chroot has none of them.
integration="sim_to_echo|invalid_frames|sequence_and_link|raw_roundtrip|selection_request|startup_errors|late_joiner"
integration+="|rate_topic|demo|realtime_gateway|embedded_controller"
# The Fast DDS attacks (3.1.2 as Debian 13 built it aborted on both without rsg's guard; 3.6 has
# upstream's fix of the second, the guard applies to both), and the published Fast DDS flaws with
# their controls (what each does to a plain participant of the chroot's Fast DDS).
integration+="|dds_attacks|fastdds_flaws"
# A data-sharing reader's delete that hangs (the control) and the egress reader's that does not.
integration+="|reader_teardown"
processes="views\.rsg_echo|interop\.cyclone|integration\.($integration)|ros2\.(standard_topics|msg_matches_field_table)"
processes+="|gateway\.embedded|cli\.rsg_frame|packaging\.install_consumer"
# rsg_record, rsg_replay and rsg_embedded_gateway complete what `cmake --install` installs, for
# packaging.install_consumer (its consumers, a view reader among them, built against the installed 3.x tree).
# unit_tests_dds: the unit tests of the folders that use Fast DDS (those of wire, transport, capture,
# mcap, foxglove and the simulator run in make test; no Fast DDS version changes them).
targets=(unit_tests_dds rsg_gateway rsg_sim rsg_echo rsg_frame rsg_status_probe rsg_views_publish rsg_view
         rsg_cyclone_echo rsg_cyclone_publish rsg_example_embedded_controller rsg_ros2_standard_echo
         rsg_generate_msg rsg_record rsg_replay rsg_embedded_gateway rsg_reader_teardown_probe
         rsg_fastdds_flaws_probe)

suite=cross
source tests/support/suite_counts.sh

start=$SECONDS
$chroot setup || exit 1
# The chroot has no ROS 2 environment, and needs none: the build computes the RIHS01 type hashes
# from the .msg files (cmake/rsg_ros2_type_hashes.cmake), which the rclpy cross tests check.
$chroot in cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRSG_FASTDDS=3 \
  -DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache > /dev/null || exit 1
$chroot in cmake --build "$build" -j "$jobs" --target "${targets[@]}" || exit 1
mkdir -p "$logs"
echo "test-fastdds3: built in the chroot in $((SECONDS - start)) s"

# 2. In the chroot: Fast DDS 3.6 on both ends.
# Not here: IngressAllocation.* (Fast DDS 3 allocates inside DataWriter::write(), the zero-allocation
# claim is 2.9's: docs/fastdds-versions.md) and packaging (it checks Debian 12's package lists);
# packaging.install_consumer runs with the process tests below.
# Side by side, one more than the cores, as make test: each test that opens DDS holds a domain of its
# own (tests/support/test_domain.py), and the RUN_SERIAL ones still run alone.
$chroot in sh -c "cd $build && ctest --output-on-failure -j $((jobs + 1)) -L unit -E '^(IngressAllocation\..*|packaging)\$'" 2>&1 | tee "$logs/unit.log" | tail -n 3
count_ctest "$logs/unit.log"
$chroot in sh -c "cd $build && ctest --output-on-failure -j $((jobs + 1)) -R '^($processes)\$'" \
  2>&1 | tee "$logs/processes.log" | grep -E '^ *[0-9]+/[0-9]+ Test|tests passed'
count_ctest "$logs/processes.log"

# 3. Across versions: Fast DDS 2.9.1 (host build) or 2.14.5 (make test-fastdds214's) processes on the
# host, 3.6 processes in the chroot, on one domain.
# Bin directories with each tool from one version: a 3.x tool is a script running it in the chroot.
mixed() {  # NAME BASE_BUILD TOOLS_FROM_3X...
  local dir=$logs/bin-$1 base=$2; shift 2
  $chroot mixed "$dir" "$checkout/$base" "$checkout/$build" "$@"
  echo "$dir"
}
# across VERSION BASE_BUILD: views (content filters included) and the pipeline, both ways between
# BASE_BUILD's Fast DDS (VERSION) and 3.6: 3.x readers on a VERSION writer's stream and VERSION
# readers on 3.x's, a 3.x gateway read by VERSION's rsg_echo and the other way, values exact.
across() {
  local version=$1 base=$2
  local gateway3 echo3 publish3
  gateway3=$(mixed "$version-gateway3" "$base" rsg_gateway)
  echo3=$(mixed "$version-echo3" "$base" rsg_echo rsg_status_probe)
  publish3=$(mixed "$version-publish3" "$base" rsg_views_publish)
  check "views_${version}_writer_3_readers" env RSG_SIM="$base/bin/rsg_sim" RSG_GATEWAY="$base/bin/rsg_gateway" \
    python3 tests/dds/echo_views_test.py --echo "$echo3/rsg_echo" \
    --publish "$base/tests/bin/rsg_views_publish" -v
  check "views_3_writer_${version}_readers" env RSG_SIM="$base/bin/rsg_sim" RSG_GATEWAY="$base/bin/rsg_gateway" \
    python3 tests/dds/echo_views_test.py --echo "$base/bin/rsg_echo" \
    --publish "$publish3/rsg_views_publish" -v
  check "sim_to_echo_3_gateway_${version}_echo" python3 tests/integration/test_sim_to_echo.py --bin "$gateway3"
  check "sim_to_echo_${version}_gateway_3_echo" python3 tests/integration/test_sim_to_echo.py --bin "$echo3"
}
if [[ ! -x $host_build/bin/rsg_echo || ! -x $host_build/tests/bin/rsg_views_publish ]]; then
  echo "test-fastdds3: no host build in $host_build (make build): 2.9 <-> 3.6 tests not run" >&2
  failed=$((failed + 1))
else
  across 2.9 "$host_build"
  gateway3=$(mixed 2.9-gateway3 "$host_build" rsg_gateway)
  gateway_echo3=$(mixed gateway_echo3 "$host_build" rsg_gateway rsg_echo)
  # ROS 2 types from ROS's own tools (rosidl -> IDL -> Cyclone, built on the host) and a 3.6 gateway:
  # its --ros2 topics read, a view on them (rsg_echo --ros2 --view, 3.6), egress from a ROS publisher.
  if [[ -x $host_build/tests/bin/rsg_ros2_cyclone_echo ]]; then
    for test in gateway egress; do
      check ros2_rosidl_cyclone_${test}_3 env RSG_ROS2_ECHO="$checkout/$host_build/tests/bin/rsg_ros2_cyclone_echo" \
        python3 tests/ros2/test_ros2_$test.py --bin "$gateway_echo3"
    done
  else
    echo "test-fastdds3: no rsg_ros2_cyclone_echo in $host_build (Debian's rosidl and Cyclone): not run" >&2
    failed=$((failed + 1))
  fi
  # ROS 2: rclpy nodes (ROS 2 Jazzy's rmw_fastrtps_cpp on Fast DDS 2.14, from `make deps`, on the
  # host) and a 3.6 gateway: its --ros2 topics, the standard ones, egress, node churn.
  deps=$(sed -n 's/^RSG_DEPS_DIR:PATH=//p' "$host_build/CMakeCache.txt")
  for test in state standard egress churn; do
    check ros2_rclpy_${test}_3_gateway env RSG_DEPS_DIR="${deps:-$checkout/.deps}" RSG_ROS_DISTRO=jazzy \
      python3 tests/ros2/test_rclpy_$test.py --bin "$gateway3"
  done
  # Filtered readers of every kind joining and leaving a 3.x gateway at 1 kHz (2.9 rsg readers, rclpy 2.14).
  check views_churn_3_gateway env RSG_DEPS_DIR="${deps:-$checkout/.deps}" RSG_ROS_DISTRO=jazzy \
    python3 tests/dds/test_views_churn.py --bin "$gateway3"
fi
if [[ ! -x $build214/bin/rsg_echo || ! -x $build214/tests/bin/rsg_views_publish ]]; then
  echo "test-fastdds3: no Fast DDS 2.14 build in $build214 (make test-fastdds214 builds it): 2.14 <-> 3.6 tests not run" >&2
  failed=$((failed + 1))
else
  across 2.14 "$build214"
fi
echo "test-fastdds3: $((SECONDS - start)) s"
echo "test-fastdds3: $passed passed, $failed failed"
[[ $failed == 0 ]]
