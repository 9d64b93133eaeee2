"""ROS 2 egress: a ROS 2 publisher of rsg_msgs/RobotState (a Cyclone writer of the type rosidl made
of ros2/rsg_msgs) on rt/<namespace>/robot_state_cmd reaches rsg_gateway --ros2's egress, which sends
each sample as the raw frame it describes, byte for byte what rsg_frame makes of the same JSON.

Needs RSG_ROS2_ECHO (rsg_ros2_cyclone_echo) in the environment; ctest sets it.
"""
import contextlib
import json
import os
import socket
import subprocess
import sys
from pathlib import Path

from harness import check, free_udp_port, main, wait_for_stats  # noqa: E402

COUNT = 20


def command_records():
    """The commands: q with -0.0 and a subnormal-adjacent 1e-300, a uint64 time above 2^63."""
    return [{"packet_number": i % 16, "group_select": 36, "data_select": [0, 0, 32, 0, 0, 8],
             "fields": {"q": [0.1 * i, -0.0, 1e-300, 2.5, -3.0, 4.0, 5.0], "time": 2 ** 63 + i}} for i in range(COUNT)]


def encode(h, records):
    """Writes the records as canonical JSON lines; returns that file and rsg_frame's frames of them."""
    source = h.dir / "cmd.jsonl"
    source.write_text("".join(json.dumps(r, separators=(",", ":")) + "\n" for r in records))
    encoded = subprocess.run([h.binary("rsg_frame"), "encode", "--hex-lines"], input=source.read_bytes(),
                             capture_output=True, timeout=60)
    check(encoded.returncode == 0, f"rsg_frame encode: {encoded.stderr.decode()}")
    expected = [bytes.fromhex(line) for line in encoded.stdout.decode().split()]
    check(len(expected) == len(records), f"rsg_frame encoded {len(expected)} frames of {len(records)}")
    return source, expected


@contextlib.contextmanager
def egress_gateway(h):
    """A started gateway in /robot1 that sends robot_state_cmd's samples to this test's UDP sink:
    yields (sink, gateway, stats)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sink:
        sink.bind(("127.0.0.1", 0))
        sink.settimeout(30)
        gateway, stats = h.gateway("gateway", "--ros2", "--ros2-namespace", "/robot1",
                                   "--send-to", f"127.0.0.1:{sink.getsockname()[1]}")
        wait_for_stats(stats, lambda s: True, "the gateway to start")
        yield sink, gateway, stats


def check_egress(h, sink, expected, stats, gateway):
    """The sink got exactly the expected frames, in order; the gateway counted them and exits 0."""
    for index, frame in enumerate(expected):
        try:
            got, _ = sink.recvfrom(4096)
        except socket.timeout:
            got = None
        check(got is not None, f"no egress frame {index}")
        check(got == frame, f"egress frame {index} differs from rsg_frame's encoding of the sample:\n"
                            f"  got  {got.hex()}\n  want {frame.hex()}")
    final = wait_for_stats(stats, lambda s: s["egress_frames_sent"] >= len(expected), "the egress counters")
    check(final["egress_samples"] == len(expected) and final["egress_unencodable"] == 0, f"egress counters {final}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


def body(h):
    ros2_echo = os.environ.get("RSG_ROS2_ECHO")
    check(ros2_echo and Path(ros2_echo).exists(), "RSG_ROS2_ECHO must name rsg_ros2_cyclone_echo")
    source, expected = encode(h, command_records())
    with egress_gateway(h) as (sink, gateway, stats):
        publisher = h.run("publisher", [ros2_echo, str(h.domain), "rt/robot1/robot_state_cmd", "publish", str(source)],
                          timeout_s=120)
        check(publisher == 0, "the ROS 2 publisher's samples were not all acknowledged by the gateway")
        check_egress(h, sink, expected, stats, gateway)


if __name__ == "__main__":
    sys.exit(main("ros2_egress", body))
