"""The standard ROS 2 topics of rsg_gateway --ros2 (--joint-states, --tf, --external-wrench) read by
real ROS 2 nodes: rclpy subscriptions of sensor_msgs/msg/JointState and geometry_msgs/msg/WrenchStamped
(the wheels of the distribution under test, RSG_ROS_DISTRO) and tf2_msgs/msg/TFMessage (built by rosidl from ROS 2's public definition in
make deps' workspace), on rmw_fastrtps_cpp.

In /robot1, fed by rsg_sim at 500 Hz: JointState at 100 Hz on /robot1/joint_states (name =
panda_joint1..7, position = q, velocity = dq, effort = tau_J of one sent frame, in order), TF every
5th frame carrying O_T_EE on the absolute /tf (panda_link0 -> panda_EE, translation = O_T_EE's
column 3, a unit quaternion rotating like O_T_EE), WrenchStamped at 50 Hz on /robot1/external_wrench
(force, torque = O_F_ext_hat_K, frame_id panda_link0), stamps within the run's wall-clock window; a
sensor_data subscription matches too. The graph API shows each writer with its ROS type name and the
RIHS01 type hash of that type.
"""
import json
import sys
import time

from harness import check, free_udp_port, main, paced_count, read_json_lines, wait_for_stats  # noqa: E402
from rclpy_common import RosEnv, hash_hint, read_messages, start_peer, wait_peer_matched  # noqa: E402
from test_ros2_standard import check_rotation, check_stamps, in_order, roughly  # noqa: E402

FRAMES = 500
RATE = "500"
TOPICS = {  # label: ROS 2 topic, type, messages expected of FRAMES frames 2 ms apart
    "joint_states": ("/robot1/joint_states", "sensor_msgs/msg/JointState", FRAMES // 5),
    "tf": ("/tf", "tf2_msgs/msg/TFMessage", FRAMES // 2 // 5),
    "wrench": ("/robot1/external_wrench", "geometry_msgs/msg/WrenchStamped", FRAMES // 10),
}


def vector(v):
    return [v["x"], v["y"], v["z"]]


def stamp(header):
    return header["stamp"]


def body(h):
    env = RosEnv(h.domain)
    port = free_udp_port()
    gateway, stats = h.gateway("gw", "--listen", f"127.0.0.1:{port}", "--expected-rate", RATE, "--ros2",
                               "--ros2-namespace", "/robot1", "--joint-states", "100", "--tf", "every:5",
                               "--external-wrench", "50")
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    for kind, (topic, type_name, _) in TOPICS.items():
        start_peer(h, env, kind, "sub", topic, type_name, "--qos", "keep_all", "--count", 0, "--idle", "3",
                   "--timeout", 60)
    start_peer(h, env, "sensor_data", "sub", TOPICS["joint_states"][0], TOPICS["joint_states"][1], "--qos",
               "sensor_data", "--count", 0, "--idle", "3", "--timeout", 60)
    for label in [*TOPICS, "sensor_data"]:
        wait_peer_matched(h, label)
    graph = start_peer(h, env, "graph", "graph", *[topic for topic, _, _ in TOPICS.values()], "--timeout", 30)

    record = h.dir / "sim.jsonl"
    started = time.time()
    sim = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count", str(FRAMES),
                        "--every", "1:q,dq,tau_J,time", "--every", "2:O_T_EE,O_F_ext_hat_K", "--record", str(record)])
    check(sim == 0, f"rsg_sim exited {sim}")
    for label in [*TOPICS, "sensor_data", "graph"]:
        check(h.wait(label, dict(h.children)[label], 90) == 0, f"the rclpy {label} node failed (see its log)")
    ended = time.time()
    check(h.stop("gw", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    sent = [frame["fields"] for frame in read_json_lines(record)]
    check(len(sent) == FRAMES, f"rsg_sim recorded {len(sent)} frames")
    got = {kind: read_messages(h, kind) for kind in TOPICS}
    # The paced topics by the robot's time as sent (the counts above assume no gap in it).
    expected = {"joint_states": paced_count([f["time"] for f in sent], 10), "tf": TOPICS["tf"][2],
                "wrench": paced_count([f["time"] for f in sent if "O_F_ext_hat_K" in f], 20)}
    print("[rclpy_standard] " + ", ".join(f"{kind} {len(got[kind])} (about {n})" for kind, n in expected.items()),
          flush=True)

    joints = got["joint_states"]
    roughly(len(joints), expected["joint_states"], "joint_states at 100 Hz of 500 Hz")
    names = [f"panda_joint{i}" for i in range(1, 8)]
    check(all(m["name"] == names for m in joints), f"joint names {joints[0]['name']}")
    in_order(joints, sent, lambda m, f: m["position"] == f["q"] and m["velocity"] == f["dq"]
             and m["effort"] == f["tau_J"], "JointState")
    check(all(m["header"]["frame_id"] == "" for m in joints), "JointState frame_id is not empty")
    check_stamps([stamp(m["header"]) for m in joints], started, ended, "joint_states")
    sensor = read_messages(h, "sensor_data")
    check(sensor and all(m in joints for m in sensor), "the sensor_data subscription got nothing, or other messages")

    posed = [f for f in sent if "O_T_EE" in f]
    tf = got["tf"]
    roughly(len(tf), expected["tf"], "tf every 5th frame with O_T_EE")
    check(all(len(m["transforms"]) == 1 for m in tf), "a TFMessage carries one transform")
    transforms = [m["transforms"][0] for m in tf]
    check(all(t["header"]["frame_id"] == "panda_link0" and t["child_frame_id"] == "panda_EE" for t in transforms),
          f"tf frames {transforms[0]['header']['frame_id']} -> {transforms[0]['child_frame_id']}")
    in_order(transforms, posed, lambda t, f: vector(t["transform"]["translation"]) == f["O_T_EE"][12:15],
             "TransformStamped")
    for t in transforms:
        pose = next(f["O_T_EE"] for f in posed if f["O_T_EE"][12:15] == vector(t["transform"]["translation"]))
        rotation = t["transform"]["rotation"]
        check_rotation(pose, [rotation["x"], rotation["y"], rotation["z"], rotation["w"]], "tf")
    check_stamps([stamp(t["header"]) for t in transforms], started, ended, "tf")

    wrenches = got["wrench"]
    roughly(len(wrenches), expected["wrench"], "external_wrench at 50 Hz of frames 2 ms apart")
    check(all(m["header"]["frame_id"] == "panda_link0" for m in wrenches), "wrench frame_id")
    in_order(wrenches, posed, lambda m, f: vector(m["wrench"]["force"]) + vector(m["wrench"]["torque"])
             == f["O_F_ext_hat_K"], "WrenchStamped")
    check_stamps([stamp(m["header"]) for m in wrenches], started, ended, "external_wrench")

    info = json.loads(h.output("graph").read_text())
    for kind, (topic, type_name, _) in TOPICS.items():
        publishers = info["publishers"][topic]
        check(len(publishers) == 1, f"{topic}: {len(publishers)} publishers in the ROS graph")
        writer = publishers[0]
        check(writer["topic_type"] == type_name, f"{topic} has type {writer['topic_type']}")
        check(writer["reliability"] == "RELIABLE" and writer["durability"] == "VOLATILE",
              f"{topic} offers {writer['reliability']} {writer['durability']}; docs/ros2.md says reliable, volatile")
        package, _, name = type_name.split("/")
        want = env.standard_type_hash(package, name)
        check(writer["topic_type_hash"] == want, f"{topic} announces type hash {writer['topic_type_hash']}, "
                                                 f"rosidl computed {want}" + hash_hint(writer["topic_type_hash"]))


if __name__ == "__main__":
    sys.exit(main("rclpy_standard", body))
