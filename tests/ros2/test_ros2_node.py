#!/usr/bin/env python3
"""The gateway inside a ROS 2 Jazzy process (issue 37, item 3): examples/ros2_node, built the way a
Jazzy user builds it -- rsg installed from a build on Fast DDS 2.14, then ROS 2 Jazzy sourced
(ros2/env.sh) and the example configured with CMake against both -- holds
rsg::gateway::EmbeddedGateway and an rcl node in one process, on one Fast DDS. rsg_sim streams frames
at 1 kHz into its gateway; a Jazzy rclpy subscription reads the node's topic and must get every
frame sent, exact and in order; the process must have mapped one libfastrtps only.

Run by tests/fastdds214/run.sh with --bin pointing at its 2.14 build's bin/ (the build tree is its
parent): tests/ros2/test_ros2_node.py --bin build-fdds214/bin
"""
import json
import os
import subprocess
import sys
from pathlib import Path

from harness import check, free_udp_port, main, wait_for  # noqa: E402
from rclpy_common import REPO, RosEnv, check_in_order, read_messages, start_peer, wait_peer_matched  # noqa: E402

COUNT = 2000
TOPIC = "/controller/robot_state"


def build_example(h, env):
    """rsg installed into a scratch prefix, then examples/ros2_node configured and built in the Jazzy
    environment, as its CMakeLists.txt tells users to. Returns the executable."""
    prefix, tree = h.dir / "prefix", h.dir / "ros2_node"
    rsg_build = Path(h.bin).resolve().parent
    install = subprocess.run(["cmake", "--install", str(rsg_build), "--prefix", str(prefix)], capture_output=True, text=True)
    check(install.returncode == 0, f"cmake --install {rsg_build}: {install.stderr.strip()[-2000:]}")
    shell = {**{k: v for k, v in os.environ.items() if k not in ("LD_LIBRARY_PATH", "CMAKE_PREFIX_PATH")},
             **env.vars}
    for step in (["cmake", "-S", str(REPO / "examples/ros2_node"), "-B", str(tree), "-G", "Ninja",
                  "-DCMAKE_BUILD_TYPE=RelWithDebInfo", f"-DCMAKE_PREFIX_PATH={prefix}",
                  "-DCMAKE_CXX_COMPILER_LAUNCHER=ccache", "-DCMAKE_C_COMPILER_LAUNCHER=ccache"],
                 ["cmake", "--build", str(tree)]):
        done = subprocess.run(step, env=shell, capture_output=True, text=True)
        with (h.dir / "example_build.log").open("a") as log:
            log.write(done.stdout + done.stderr)
        check(done.returncode == 0, f"{' '.join(step[:3])}: failed, see {h.dir / 'example_build.log'}:\n"
                                    f"{(done.stdout + done.stderr)[-3000:]}")
    return tree / "rsg_ros2_node", prefix


def body(h):
    env = RosEnv(h.domain, "jazzy")
    node_binary, prefix = build_example(h, env)
    port = free_udp_port()
    config = h.dir / "gateway.yaml"
    config.write_text(f"listen: 127.0.0.1:{port}\ndomain: {h.domain}\nprofiles: {prefix}/share/rsg/xml_profiles\n")
    # As a user runs it: ROS 2 Jazzy sourced, nothing else on the library path.
    node = h.start("node", ["env", "-u", "LD_LIBRARY_PATH", f"ROS_DOMAIN_ID={h.domain}", f"RSG_DEPS_DIR={env.deps}",
                            "RSG_ROS_DISTRO=jazzy", "bash", "-c", '. "$0" && exec "$@"', str(REPO / "ros2/env.sh"),
                            str(node_binary), str(config)])
    node_out = h.output("node")
    wait_for(lambda: node.poll() is not None or "frames on UDP" in node_out.read_text(errors="replace"),
             "the node's gateway to start")
    check(node.poll() is None, f"rsg_ros2_node exited {node.poll()} at start")

    # One Fast DDS in the process: rsg's and rmw_fastrtps's are the same library.
    maps = Path(f"/proc/{node.pid}/maps").read_text()
    fastdds = sorted({line.split()[-1] for line in maps.splitlines() if "libfastrtps.so" in line or "libfastdds.so" in line})
    check(len(fastdds) == 1 and "libfastrtps.so.2.14" in fastdds[0], f"Fast DDS libraries mapped: {fastdds}")
    rcl = [line for line in maps.splitlines() if line.endswith("/librcl.so")]
    check(rcl, "librcl.so is not mapped: no ROS 2 node in the process")

    start_peer(h, env, "sub", "sub", TOPIC, "rsg_msgs/msg/RobotState", "--qos", "keep_all", "--count", COUNT,
               "--timeout", 90)
    wait_peer_matched(h, "sub")
    wait_for(lambda: "1 subscription(s) matched" in node_out.read_text(errors="replace"),
             "the node's publisher to match the subscription")
    record = h.dir / "sent.jsonl"
    check(h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", str(COUNT),
                        "--record", str(record)], timeout_s=60) == 0, "rsg_sim failed")
    check(h.wait("sub", dict(h.children)["sub"], 90) == 0, "the Jazzy subscription did not get every message")
    sent = [json.loads(line) for line in record.read_text().splitlines()]
    got = read_messages(h, "sub")
    check(len(got) == COUNT, f"the Jazzy subscription got {len(got)} messages of {COUNT}")
    check(check_in_order("rsg_ros2_node", sent, got, list(got[0])) == list(range(COUNT)),
          "the messages are not the frames sent, in order")
    check(h.stop("node", node) == 0, "rsg_ros2_node did not exit 0 on SIGTERM")
    last = node_out.read_text(errors="replace").strip().splitlines()[-1]
    check(last == f"rsg_ros2_node: {COUNT} states published, 0 dropped (ring full)", f"the node said: {last}")
    print(f"[ros2_node] {COUNT} frames at 1 kHz through the gateway and the rcl node in one process "
          f"({fastdds[0].rsplit('/', 1)[-1]}), read exact by a Jazzy rclpy subscription", flush=True)


if __name__ == "__main__":
    sys.exit(main("ros2_node", body))
