"""rsg_gateway --ros2 read by real ROS 2 nodes: rclpy on rmw_fastrtps_cpp (ROS 2 Jazzy:
Fast DDS 2.14) with the rsg_msgs that Jazzy's ament_cmake + rosidl built (make deps), against the
gateway's own Fast DDS (Debian 12's 2.9.1; a 3.6 gateway in make test-fastdds3).

In the root namespace and in /robot1, fed by rsg_sim:
- a subscription with rclpy's default QoS (reliable, volatile, keep last 10) gets the stream in
  order, every message equal member by member to a frame rsg_sim sent (fields the frame lacked are 0);
- one with qos_profile_sensor_data (best effort, keep last 5) gets only such messages;
- a transient-local subscription (depth 10) started after the stream gets its history: messages
  equal to sent frames in order, the last 10 being the stream's last 10 (the writer sends all it
  keeps; the reader's keep-last 10 may drop some of them before rclpy takes them);
- `ros2 topic info -v` through rclpy's graph API (get_publishers_info_by_topic): rsg's writers of
  robot_state and gateway_status with their ROS type names, the QoS docs/ros2.md states, and the
  RIHS01 type hash rosidl computed from the .msg (USER_DATA typehash=...;);
- in /robot1, a content-filtered subscription with docs/ros2.md's expression
  ("group_present[2] = TRUE AND group_present[3] = TRUE") gets exactly the frames that carry both.
"""
import json
import sys

from harness import check, free_udp_port, main, read_json_lines, wait_for_stats  # noqa: E402
from rclpy_common import RosEnv, check_in_order, graph_query, hash_hint, read_messages, start_peer, wait_peer_matched

COUNT = 200
RATE = "200"
FILTER = "group_present[2] = TRUE AND group_present[3] = TRUE"


def run(h, env, namespace):
    label = "gw" + namespace.replace("/", "_")
    ns = namespace or ""
    port = free_udp_port()
    flags = ["--ros2"] + (["--ros2-namespace", namespace] if namespace else [])
    gateway, stats = h.gateway(label, "--listen", f"127.0.0.1:{port}", "--expected-rate", RATE, *flags)
    wait_for_stats(stats, lambda s: True, "the gateway to start")

    state = f"{ns}/robot_state"
    peers = {"default": ["--qos", "default", "--count", COUNT * 9 // 10, "--idle", "2"],
             "sensor": ["--qos", "sensor_data", "--count", 0, "--idle", "3"]}
    if namespace:
        peers["filtered"] = ["--qos", "keep_all", "--count", 0, "--idle", "3", "--filter", FILTER]
    for name, args in peers.items():
        start_peer(h, env, f"{label}_{name}", "sub", state, "rsg_msgs/msg/RobotState", "--timeout", 60, *args)
    wait_for_stats(stats, lambda s: s["state_readers"] >= len(peers), f"{len(peers)} rclpy subscriptions to match")
    for name in peers:
        wait_peer_matched(h, f"{label}_{name}")

    record = h.dir / f"{label}.sim.jsonl"
    sim = h.run(label + "_sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count",
                                 str(COUNT), "--every", "1:q,dq,tau_J,time", "--every", "4:all", "--record", str(record)])
    check(sim == 0, f"rsg_sim exited {sim}")
    sent = read_json_lines(record)
    check(len(sent) == COUNT, f"rsg_sim recorded {len(sent)} frames")
    wait_for_stats(stats, lambda s: s["frames_published"] >= COUNT, "the gateway to publish every frame")

    # Joins after the stream: transient-local gets the writer's history.
    start_peer(h, env, f"{label}_late", "sub", state, "rsg_msgs/msg/RobotState", "--qos", "transient_local",
               "--depth", 10, "--count", 0, "--idle", "3", "--timeout", 60)

    for name in [*peers, "late"]:
        process = dict(h.children)[f"{label}_{name}"]
        check(h.wait(f"{label}_{name}", process, 90) == 0, f"{label}_{name} ended in failure (see its log)")
    graph_query(h, env, f"{label}_graph", state, f"{ns}/gateway_status", "--timeout", 30)

    got = read_messages(h, f"{label}_default")
    check(len(got) >= COUNT * 9 // 10, f"the default-QoS subscription got {len(got)} of {COUNT}")
    order = list(got[0])
    positions = check_in_order(f"{namespace or '/'} default QoS", sent, got, order)
    check(positions[0] == 0, f"the default-QoS subscription missed the first frame (its first is frame {positions[0]})")

    sensor = read_messages(h, f"{label}_sensor")
    check(sensor, "the sensor_data subscription got nothing")
    check_in_order(f"{namespace or '/'} sensor_data", sent, sensor, order)

    late = read_messages(h, f"{label}_late")
    check(len(late) >= 10, f"the transient-local subscription got {len(late)} samples on joining (depth 10)")
    late_positions = check_in_order(f"{namespace or '/'} transient_local", sent, late, order)
    # The writer sends its whole history (keep-last 1000); the reader's keep-last 10 may drop some of
    # it before rclpy takes them, but what it keeps last is the stream's last 10 frames.
    check(late_positions[-10:] == list(range(COUNT - 10, COUNT)),
          f"the transient-local subscription's last 10 samples are frames {late_positions[-10:]}, "
          f"not the stream's last 10")

    if namespace:
        filtered = read_messages(h, f"{label}_filtered")
        wanted = [index for index, frame in enumerate(sent) if frame["group_select"] & 0b1100 == 0b1100]
        check(check_in_order("content filter", sent, filtered, order) == wanted,
              f"the content-filtered subscription got {len(filtered)} samples, not exactly the {len(wanted)} "
              f"frames carrying groups 2 and 3")
        err = (h.dir / f"{label}_filtered.err").read_text()
        check("content filter enabled: True" in err, "rmw_fastrtps did not enable the content filter")

    info = json.loads(h.output(label + "_graph").read_text())
    check_graph(env, info, ns)
    check(h.stop(label, gateway) == 0, "the gateway did not exit 0 on SIGTERM")


def check_graph(env, info, ns):
    """What `ros2 topic info -v` shows of rsg's two writers."""
    for topic, type_name, deadline in ((f"{ns}/robot_state", "RobotState", 100_000_000),
                                       (f"{ns}/gateway_status", "GatewayStatus", None)):
        publishers = info["publishers"][topic]
        check(len(publishers) == 1, f"{topic}: {len(publishers)} publishers in the ROS graph")
        writer = publishers[0]
        check(writer["topic_type"] == f"rsg_msgs/msg/{type_name}", f"{topic} has type {writer['topic_type']}")
        check(writer["reliability"] == "RELIABLE" and writer["durability"] == "TRANSIENT_LOCAL",
              f"{topic} offers {writer['reliability']} {writer['durability']}, docs/ros2.md says reliable, "
              f"transient-local")
        if deadline:
            check(writer["deadline_ns"] == deadline, f"{topic} offers a deadline of {writer['deadline_ns']} ns")
        want = env.type_hash("rsg_msgs", type_name)
        check(writer["topic_type_hash"] == want,
              f"{topic} announces type hash {writer['topic_type_hash']}, rosidl computed {want}"
              + hash_hint(writer["topic_type_hash"]))
        check(info["topics"].get(topic) == [f"rsg_msgs/msg/{type_name}"], f"{topic} in get_topic_names_and_types: "
                                                                          f"{info['topics'].get(topic)}")


def body(h):
    env = RosEnv(h.domain)
    run(h, env, "")
    run(h, env, "/robot1")


if __name__ == "__main__":
    sys.exit(main("rclpy_state", body))
