"""The standard ROS 2 topics of rsg_gateway (--joint-states, --tf, --external-wrench), read by Cyclone
readers built from rsg's idl/ros2 (the public ROS message definitions, ROS 2's DDS type names):

1. --ros2 in a namespace, fed by rsg_sim at 1 kHz: joint_states at 100 Hz, tf every 10th frame that
   carries O_T_EE, external_wrench at 50 Hz. Each message holds exactly the values of one frame the
   sim sent (position = q, velocity = dq, effort = tau_J; translation = O_T_EE's; the quaternion
   rotates like O_T_EE's rotation part; force, torque = O_F_ext_hat_K), in order, stamped with the
   host's wall clock during the run; the message counts follow the decimation (generous tolerance).
   A best-effort (sensor_data) reader of joint_states matches too and gets only such messages.
2. Plain DDS, every frame, hand-made frames: quaternions of known poses come back (up to sign),
   configured joint names and frames are used, a frame without q publishes no JointState, one
   without dq gives an empty velocity, wrench values come back exactly.

Needs RSG_ROS2_STANDARD_ECHO (rsg_ros2_standard_echo) in the environment; ctest sets it.
"""
import json
import math
import os
import random
import socket
import subprocess
import sys
import time
from pathlib import Path

from harness import (check, free_udp_port, main, paced_count, read_json, read_json_lines,  # noqa: E402
                     wait_for, wait_for_stats)

FRAMES = 2000  # 2 s at 1 kHz
IDLE_S = "8"   # a reader stops this long after the last message


def echo():
    path = os.environ.get("RSG_ROS2_STANDARD_ECHO")
    check(path and Path(path).exists(), "RSG_ROS2_STANDARD_ECHO must name rsg_ros2_standard_echo")
    return path


def start_readers(h, label, topics, min_counts, qos=()):
    readers = {}
    for kind, topic in topics.items():
        name = f"{label}_{kind}"
        readers[kind] = (name, h.start(name, [echo(), str(h.domain), topic, kind, str(min_counts[kind]),
                                              "60", IDLE_S, *qos]))
    for kind, (name, _) in readers.items():
        wait_for(lambda: "matched" in (h.dir / f"{name}.err").read_text(), f"{name} to match the gateway's writer")
    return readers


def collect(h, readers):
    got = {}
    for kind, (name, process) in readers.items():
        check(h.wait(name, process, 90) == 0, f"{name} got fewer messages than expected")
        got[kind] = read_json_lines(h.output(name))
    return got


def rotation_of_quaternion(x, y, z, w):
    """Row-major 3x3 rotation of a unit quaternion."""
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def check_rotation(pose, quaternion, what):
    """pose: O_T_EE column-major (element 4*c + r is row r, column c)."""
    norm = math.sqrt(sum(c * c for c in quaternion))
    check(abs(norm - 1) < 1e-9, f"{what}: quaternion {quaternion} is not a unit one")
    rotation = rotation_of_quaternion(*quaternion)
    for r in range(3):
        for c in range(3):
            check(abs(rotation[r][c] - pose[4 * c + r]) < 1e-9,
                  f"{what}: quaternion {quaternion} rotates unlike O_T_EE ({r},{c}): "
                  f"{rotation[r][c]} vs {pose[4 * c + r]}")


def check_stamps(headers, started, ended, what):
    stamps = [header["sec"] + header["nanosec"] * 1e-9 for header in headers]
    check(all(started <= s <= ended for s in stamps), f"{what}: stamps outside the run's wall-clock window")
    check(stamps == sorted(stamps), f"{what}: stamps go back")


def in_order(messages, sent, key, what):
    """Each message matches `key(message, frame)` for a frame sent, later frames for later messages."""
    position = 0
    for index, message in enumerate(messages):
        while position < len(sent) and not key(message, sent[position]):
            position += 1
        check(position < len(sent), f"{what} {index} is no frame sent (or out of order): {message}")
        position += 1


def roughly(count, expected, what):
    check(0.9 * expected <= count <= 1.1 * expected, f"{what}: {count} messages, expected about {expected}")


def ros2_namespace_run(h):
    port = free_udp_port()
    gateway, stats = h.gateway("ros2", "--listen", f"127.0.0.1:{port}", "--expected-rate", "1000", "--ros2",
                               "--ros2-namespace", "/robot1", "--joint-states", "100", "--tf", "every:10",
                               "--external-wrench", "50")
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    topics = {"joint_states": "rt/robot1/joint_states", "tf": "rt/tf", "wrench": "rt/robot1/external_wrench"}
    # 2000 frames of robot time 0..1999 ms; O_T_EE and the wrench in every second frame.
    expected = {"joint_states": FRAMES // 10, "tf": FRAMES // 2 // 10, "wrench": FRAMES // 20}
    readers = start_readers(h, "ros2", topics, {kind: int(0.9 * n) for kind, n in expected.items()})
    # rclcpp's sensor_data preset (best effort) matches the writers too: it gets at least one message.
    best_effort = start_readers(h, "ros2_sensor_data", {"joint_states": topics["joint_states"]}, {"joint_states": 1},
                                ["sensor_data"])
    # The readers' "matched" is their side of discovery; the writers count them once theirs is done.
    wait_for_stats(stats, lambda s: s["standard_readers"] >= 4, "the standard topics' writers to match 4 readers")

    record = h.dir / "ros2.sim.jsonl"
    started = time.time()
    sim = h.run("ros2_sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", str(FRAMES),
                             "--every", "1:q,dq,tau_J,time", "--every", "2:O_T_EE,O_F_ext_hat_K", "--record", str(record)])
    check(sim == 0, f"rsg_sim exited {sim}")
    got = collect(h, readers)
    sensor_data = collect(h, best_effort)["joint_states"]
    ended = time.time()
    check(h.stop("ros2", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    sent = [frame["fields"] for frame in read_json_lines(record)]
    check(len(sent) == FRAMES, f"the sim recorded {len(sent)} frames")
    # The paced topics by the robot's time as sent (the counts above assume no gap in it).
    expected["joint_states"] = paced_count([f["time"] for f in sent], 10)
    expected["wrench"] = paced_count([f["time"] for f in sent if "O_F_ext_hat_K" in f], 20)
    print(f"[ros2_standard] {FRAMES} frames -> " + ", ".join(f"{kind} {len(got[kind])} (expected about {n})"
                                                          for kind, n in expected.items()), flush=True)

    joints = got["joint_states"]
    roughly(len(joints), expected["joint_states"], "joint_states at 100 Hz of 1 kHz")
    names = [f"panda_joint{i}" for i in range(1, 8)]
    check(all(m["name"] == names for m in joints), f"joint names {joints[0]['name']}")
    in_order(joints, sent, lambda m, f: m["position"] == f["q"] and m["velocity"] == f["dq"]
             and m["effort"] == f["tau_J"], "JointState")
    check_stamps(joints, started, ended, "joint_states")
    check(all(m in joints for m in sensor_data), "the sensor_data reader got a JointState the reliable one did not")

    posed = [f for f in sent if "O_T_EE" in f]
    tf = got["tf"]
    roughly(len(tf), expected["tf"], "tf every 10th frame with O_T_EE")
    check(all(len(m["transforms"]) == 1 for m in tf), "a TFMessage carries one transform")
    transforms = [m["transforms"][0] for m in tf]
    check(all(t["frame_id"] == "panda_link0" and t["child_frame_id"] == "panda_EE" for t in transforms),
          f"tf frames {transforms[0]['frame_id']} -> {transforms[0]['child_frame_id']}")
    in_order(transforms, posed, lambda t, f: t["translation"] == f["O_T_EE"][12:15], "TransformStamped")
    for t in transforms:
        pose = next(f["O_T_EE"] for f in posed if f["O_T_EE"][12:15] == t["translation"])
        check_rotation(pose, t["rotation"], "tf")
    check_stamps(transforms, started, ended, "tf")

    wrenches = got["wrench"]
    roughly(len(wrenches), expected["wrench"], "external_wrench at 50 Hz of frames 2 ms apart")
    check(all(m["frame_id"] == "panda_link0" for m in wrenches), "wrench frame_id")
    check(all(m["force"] + m["torque"] in [f["O_F_ext_hat_K"] for f in posed] for m in wrenches),
          "a wrench that no frame carried")
    check_stamps(wrenches, started, ended, "external_wrench")


def quaternion_pose(rng):
    """A random unit quaternion (w >= 0) and the pose it makes, column-major."""
    q = [rng.gauss(0, 1) for _ in range(4)]
    n = math.sqrt(sum(c * c for c in q))
    x, y, z, w = (c / n for c in q)
    if w < 0:
        x, y, z, w = -x, -y, -z, -w
    rotation = rotation_of_quaternion(x, y, z, w)
    translation = [rng.uniform(-1, 1) for _ in range(3)]
    pose = [0.0] * 16
    for r in range(3):
        for c in range(3):
            pose[4 * c + r] = rotation[r][c]
        pose[12 + r] = translation[r]
    pose[15] = 1.0
    return [x, y, z, w], pose


def record_of(index, fields):
    """Canonical JSON of a frame carrying `fields` (a dict in field-index order)."""
    bits = {"O_T_EE": (0, 0x01), "tau_J": (2, 0x04), "q": (2, 0x20), "dq": (2, 0x80), "O_F_ext_hat_K": (3, 0x80),
            "time": (5, 0x08)}
    data_select = [0] * 6
    for name in fields:
        group, mask = bits[name]
        data_select[group] |= mask
    group_select = sum(1 << g for g in range(6) if data_select[g])
    return json.dumps({"packet_number": index % 16, "group_select": group_select, "data_select": data_select,
                       "fields": fields}, separators=(",", ":"))


def plain_dds_run(h):
    rng = random.Random(10)
    frames, quaternions = [], []
    for i in range(40):
        quaternion, pose = quaternion_pose(rng)
        fields = {"O_T_EE": pose}
        if i % 5 != 3:  # some frames without joints: no JointState for them
            fields["tau_J"] = [rng.uniform(-80, 80) for _ in range(7)]
            fields["q"] = [rng.uniform(-2.8, 2.8) for _ in range(7)]
            if i % 2 == 0:
                fields["dq"] = [rng.uniform(-2, 2) for _ in range(7)]
        fields["O_F_ext_hat_K"] = [rng.uniform(-50, 50) for _ in range(6)]
        fields["time"] = 1000 + i
        frames.append(fields)
        quaternions.append(quaternion)
    lines = "\n".join(record_of(i, f) for i, f in enumerate(frames)) + "\n"
    encoded = subprocess.run([h.binary("rsg_frame"), "encode", "--hex-lines"], input=lines.encode(),
                             capture_output=True, timeout=60)
    check(encoded.returncode == 0, f"rsg_frame encode: {encoded.stderr.decode()}")
    datagrams = [bytes.fromhex(line) for line in encoded.stdout.decode().split()]
    check(len(datagrams) == len(frames), f"rsg_frame encoded {len(datagrams)} frames")

    port = free_udp_port()
    names = [f"arm_j{i}" for i in range(1, 8)]
    gateway, stats = h.gateway("plain", "--listen", f"127.0.0.1:{port}", "--joint-states", "every:1", "--tf", "10000",
                               "--external-wrench", "every:1", "--joint-names", ",".join(names),
                               "--base-frame", "world", "--ee-frame", "tool0", "--wrench-frame", "tool0")
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    with_joints = [f for f in frames if "q" in f]
    topics = {"joint_states": "joint_states", "tf": "tf", "wrench": "external_wrench"}
    readers = start_readers(h, "plain", topics,
                            {"joint_states": len(with_joints), "tf": len(frames), "wrench": len(frames)})
    wait_for_stats(stats, lambda s: s["standard_readers"] >= 3, "the standard topics' writers to match 3 readers")
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as robot:
        for datagram in datagrams:
            robot.sendto(datagram, ("127.0.0.1", port))
            time.sleep(0.002)  # a robot's pace; the rates go by the frames' time (1 ms apart), not by this
    got = collect(h, readers)
    check(h.stop("plain", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    # 40 frames leave at most 40 snapshots, fewer than the ring holds: none can have been dropped.
    dropped = read_json(stats)["standard_dropped"]
    check(dropped == 0, f"standard_dropped {dropped} for fewer snapshots than the ring holds")

    joints = got["joint_states"]
    check(len(joints) == len(with_joints), f"{len(joints)} JointStates for {len(with_joints)} frames with q")
    for message, frame in zip(joints, with_joints):
        check(message["name"] == names, f"joint names {message['name']}")
        check(message["position"] == frame["q"] and message["effort"] == frame["tau_J"], "JointState values")
        check(message["velocity"] == frame.get("dq", []), "velocity must be dq, empty when dq is absent")
    tf = [m["transforms"][0] for m in got["tf"]]
    check(len(tf) == len(frames), f"{len(tf)} TFMessages for {len(frames)} frames")
    for t, frame, quaternion in zip(tf, frames, quaternions):
        check(t["frame_id"] == "world" and t["child_frame_id"] == "tool0", "configured TF frames")
        check(t["translation"] == frame["O_T_EE"][12:15], "translation")
        sign = 1 if t["rotation"][3] >= 0 else -1
        check(all(abs(sign * a - b) < 1e-12 for a, b in zip(t["rotation"], quaternion)),
              f"quaternion {t['rotation']} of the pose made from {quaternion}")
    wrenches = got["wrench"]
    check(len(wrenches) == len(frames), f"{len(wrenches)} wrenches for {len(frames)} frames")
    for message, frame in zip(wrenches, frames):
        check(message["frame_id"] == "tool0", "configured wrench frame")
        check(message["force"] + message["torque"] == frame["O_F_ext_hat_K"], "wrench values")


def body(h):
    ros2_namespace_run(h)
    plain_dds_run(h)


if __name__ == "__main__":
    sys.exit(main("ros2_standard", body))
