"""The ROS 2 side of make bench's ros2_rate suite (ros2_rate.py): a plain rclpy node, run with the
Python of the project's ROS 2 environment (ros2/env.sh: Jazzy), never imported.

  sub --topic T --settle S --seconds S
      one subscription of rsg_msgs/msg/RobotState with rclpy's default QoS (reliable, volatile,
      keep last 10), spun by rclpy.spin_once as rclpy.spin does; once the first message came and
      --settle seconds passed, it keeps the arrival time (monotonic clock, taken first thing in the
      callback) and `time` member of every message for --seconds, then prints one JSON line:
      received, the span of `time` values, lost (values missing from that span: one frame per
      millisecond at 1 kHz, rsg_sim's robot clock; packet_number rolls over at 16), duplicates,
      rate, inter-arrival p50/p99/max and the process's CPU over the window
  pub --topic T --rate HZ --seconds S
      a publisher of rsg_msgs/msg/RobotState with the default QoS, `time` counting from 1,
      published from an rclpy timer of 1/HZ s (the way a ROS 2 node publishes at a rate) once a
      subscription matched, for --seconds; prints one JSON line: published, rate achieved
"""
import argparse
import json
import sys
import time

import rclpy
from rclpy.event_handler import PublisherEventCallbacks
from rclpy.qos import QoSProfile
from rsg_msgs.msg import RobotState


def percentile(sorted_values, fraction):
    if not sorted_values:
        return None
    return sorted_values[min(len(sorted_values) - 1, int(fraction * len(sorted_values)))]


def subscribe(args):
    node = rclpy.create_node("rsg_bench_rate_sub")
    arrivals = []  # (monotonic ns, time member) of every message; the window is cut afterwards
    clock = time.monotonic_ns

    def on_message(message):
        arrivals.append((clock(), message.time))

    node.create_subscription(RobotState, args.topic, on_message, QoSProfile(depth=10))
    deadline = time.monotonic() + args.timeout
    while not arrivals:
        if time.monotonic() > deadline:
            print(json.dumps({"error": f"no message within {args.timeout} s"}), flush=True)
            return 1
        rclpy.spin_once(node, timeout_sec=0.1)
    start_ns = arrivals[0][0] + int(args.settle * 1e9)
    end_ns = start_ns + int(args.seconds * 1e9)
    cpu_start = None
    while clock() < end_ns:
        if cpu_start is None and clock() >= start_ns:
            cpu_start = time.process_time()
        rclpy.spin_once(node, timeout_sec=0.1)
    cpu = time.process_time() - (cpu_start if cpu_start is not None else time.process_time())
    window = [(t, n) for t, n in arrivals if start_ns <= t < end_ns]
    if len(window) < 2:
        print(json.dumps({"error": f"{len(window)} messages in the window"}), flush=True)
        return 1
    numbers = [n for _, n in window]
    unique = set(numbers)
    span = (max(numbers) - min(numbers)) // args.step + 1
    gaps = sorted((b - a) / 1e6 for (a, _), (b, _) in zip(window, window[1:]))
    print(json.dumps({
        "received": len(window), "seconds": args.seconds, "rate_hz": round(len(window) / args.seconds, 1),
        "first_time": min(numbers), "last_time": max(numbers), "span": span, "lost": span - len(unique),
        "duplicates": len(window) - len(unique),
        "out_of_order": sum(1 for a, b in zip(numbers, numbers[1:]) if b < a),
        "interarrival_ms": {"p50": round(percentile(gaps, 0.50), 3), "p99": round(percentile(gaps, 0.99), 3),
                            "max": round(gaps[-1], 3)},
        "cpu_pct": round(100.0 * cpu / args.seconds, 1)}), flush=True)
    return 0


def publish(args):
    node = rclpy.create_node("rsg_bench_rate_pub")
    matched = [0]

    def on_matched(info):
        matched[0] = info.current_count

    publisher = node.create_publisher(RobotState, args.topic, QoSProfile(depth=10),
                                      event_callbacks=PublisherEventCallbacks(matched=on_matched))
    deadline = time.monotonic() + args.timeout
    while not matched[0]:
        if time.monotonic() > deadline:
            print(json.dumps({"error": f"no subscription matched within {args.timeout} s"}), flush=True)
            return 1
        rclpy.spin_once(node, timeout_sec=0.1)
    message = RobotState()
    message.group_select = 0x3f
    message.group_present = [True] * len(message.group_present)
    sent = [0]

    def on_timer():
        sent[0] += 1
        message.time = sent[0]
        publisher.publish(message)

    node.create_timer(1.0 / args.rate, on_timer)
    start = time.monotonic()
    end = start + args.seconds
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.1)
    elapsed = time.monotonic() - start
    print(json.dumps({"published": sent[0], "seconds": round(elapsed, 2), "rate_hz": round(sent[0] / elapsed, 1)}),
          flush=True)
    return 0


def main():
    parser = argparse.ArgumentParser()
    commands = parser.add_subparsers(dest="command", required=True)
    sub = commands.add_parser("sub")
    sub.add_argument("--topic", default="/robot_state")
    sub.add_argument("--settle", type=float, default=3)
    sub.add_argument("--seconds", type=float, default=60)
    sub.add_argument("--timeout", type=float, default=60, help="for the first message")
    sub.add_argument("--step", type=int, default=1, help="`time` between two frames [ms]: 1 at 1 kHz")
    pub = commands.add_parser("pub")
    pub.add_argument("--topic", default="/robot_state")
    pub.add_argument("--rate", type=float, default=1000)
    pub.add_argument("--seconds", type=float, default=70)
    pub.add_argument("--timeout", type=float, default=60, help="for a subscription to match")
    args = parser.parse_args()
    rclpy.init()
    try:
        return {"sub": subscribe, "pub": publish}[args.command](args)
    finally:
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main())
