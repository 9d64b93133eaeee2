"""rsg_gateway --ros2 seen by a reader built from ROS's own tools: rosidl turned ros2/rsg_msgs into
IDL, idlc compiled it, and that Cyclone reader (rclcpp's `default` and `sensor_data` QoS) receives
exactly the values rsg_sim sent, in order, on ROS 2 topic and type names, in the root namespace and in one;
a view (content filter) on that topic still delivers exactly its samples.

Needs RSG_ROS2_ECHO (rsg_ros2_cyclone_echo) in the environment; ctest sets it.
"""
import os
import sys
from pathlib import Path

from harness import (check, free_udp_port, main, read_json, read_json_lines, wait_for, wait_for_stats,  # noqa: E402
                     wait_reader_matched)

COUNT = 200
RATE = "200"


def run_gateway(h, namespace):
    label = "gateway" + namespace.replace("/", "_")
    ros2_echo = os.environ.get("RSG_ROS2_ECHO")
    check(ros2_echo and Path(ros2_echo).exists(), "RSG_ROS2_ECHO must name rsg_ros2_cyclone_echo")
    prefix = "rt" + namespace
    port = free_udp_port()
    flags = ["--ros2"] + (["--ros2-namespace", namespace] if namespace else [])
    gateway, stats = h.gateway(label, "--listen", f"127.0.0.1:{port}", "--expected-rate", RATE, *flags)
    wait_for_stats(stats, lambda s: True, "the gateway to start")

    # rclcpp's default is keep-last 10: a reader busy elsewhere may lose the oldest of a burst, so it
    # is asked for 90 % of the stream and checked for exact values in order, not for completeness.
    reliable = h.start(label + "_default", [ros2_echo, str(h.domain), prefix + "/robot_state", "state", "default",
                                            str(COUNT * 9 // 10), "30"])
    best_effort = h.start(label + "_sensor", [ros2_echo, str(h.domain), prefix + "/robot_state", "state",
                                              "sensor_data", str(COUNT // 2), "30"])
    # A view (content filter) on the ROS-typed topic, through Fast DDS: groups 0 only.
    view = h.start(label + "_view", [h.binary("rsg_echo"), "--domain", str(h.domain), "--ros2", *flags[1:],
                                     "--view", "view_poses", "--json", "--count", str(COUNT // 4), "--timeout", "30"])
    status = h.start(label + "_status", [ros2_echo, str(h.domain), prefix + "/gateway_status", "status", "default",
                                         "2", "30"])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 3, "both ROS-typed readers to match the state writer")
    for reader in ("_default", "_sensor"):
        wait_for(lambda: "matched" in (h.dir / f"{label}{reader}.err").read_text(), f"{label}{reader} to match")
    wait_reader_matched(h, label + "_view", "rsg_echo")  # it must see every pose: matched before the first

    record = h.dir / f"{label}.sim.jsonl"
    sim = h.run(label + "_sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count",
                                 str(COUNT), "--every", "1:q,dq,tau_J,time", "--every", "4:all", "--record", str(record)])
    check(sim == 0, f"rsg_sim exited {sim}")
    check(h.wait(label + "_default", reliable, 30) == 0, "the reliable (default QoS) reader missed over 10 %")
    check(h.wait(label + "_sensor", best_effort, 30) == 0, "the sensor_data (best effort) reader got nothing")
    check(h.wait(label + "_view", view, 30) == 0, "rsg_echo --ros2 --view view_poses did not get its samples")
    check(h.wait(label + "_status", status, 30) == 0, "no GatewayStatus on " + prefix + "/gateway_status")
    check(h.stop(label, gateway) == 0, "the gateway did not exit 0 on SIGTERM")

    sent = read_json_lines(record)
    check(len(sent) == COUNT, f"the sim recorded {len(sent)} frames")
    got = read_json_lines(h.output(label + "_default"))
    check(len(got) == COUNT * 9 // 10, f"default reader printed {len(got)} samples")
    check(got[0] == sent[0], f"{namespace or '/'} first sample differs:\n  sent {sent[0]}\n  got  {got[0]}")
    position = 0
    for index, actual in enumerate(got):  # exact values, in the order sent
        while position < len(sent) and sent[position] != actual:
            position += 1
        check(position < len(sent), f"{namespace or '/'} sample {index} was not sent (or out of order): {actual}")
    sensor = read_json_lines(h.output(label + "_sensor"))
    check(all(sample in sent for sample in sensor), "the sensor_data reader got a sample that was not sent")

    poses = [sample for sample in sent if sample["group_select"] & 1]
    check(read_json_lines(h.output(label + "_view")) == poses, "the view on the ROS 2 topic got other samples")

    statuses = read_json_lines(h.output(label + "_status"))
    final = read_json(stats)
    check(len(statuses) == 2, f"status reader printed {len(statuses)} samples")
    check(statuses[-1]["frames_received"] <= final["frames_received"], "status counters ahead of the stats file")
    check(statuses[-1]["source"] in ("", final["source"]), f"status source {statuses[-1]['source']!r}")
    # The last member, read through the .msg's layout; no standard topics here, so nothing dropped.
    check(statuses[-1]["standard_dropped"] == 0 and final["standard_dropped"] == 0,
          f"standard_dropped {statuses[-1]['standard_dropped']} / {final['standard_dropped']} without standard topics")


def body(h):
    run_gateway(h, "")
    run_gateway(h, "/robot1")


if __name__ == "__main__":
    sys.exit(main("ros2_gateway", body))
