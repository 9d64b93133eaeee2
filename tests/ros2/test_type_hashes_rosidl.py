"""rosidl is the judge of rsg's RIHS01 type hashes: the hashes every build computes without ROS 2
(ros2/type_hashes.py from the .msg files, into the header the gateway announces them from) are the
ones rosidl computes, for every type rsg_gateway publishes: rsg_msgs' RobotState (run through
rosidl_adapter and rosidl_generator_type_description from the repository's .msg) and
GatewayStatus, and the standard sensor_msgs/JointState, tf2_msgs/TFMessage and
geometry_msgs/WrenchStamped (rosidl's type descriptions of the ROS 2 wheels and of make deps'
tf2_msgs build; Jazzy's rosidl). Needs make deps' ROS 2 environment; fails saying so without it.

RSG_TYPE_HASHES_HEADER names the header the build generated (CMake sets it). docs/ros2.md's table of
the hashes must list the same.
"""
import os
import re
import subprocess
import sys
from pathlib import Path

from harness import check, main  # noqa: E402
from rclpy_common import REPO, RosEnv  # noqa: E402

RSG_TYPES = ["rsg_msgs/msg/RobotState", "rsg_msgs/msg/GatewayStatus"]
STANDARD_TYPES = ["sensor_msgs/msg/JointState", "tf2_msgs/msg/TFMessage", "geometry_msgs/msg/WrenchStamped"]


def header_hashes(path):
    text = path.read_text()
    return dict(re.findall(r'\{"([\w/]+)", "(RIHS01_[0-9a-f]{64})"\}', text))


def body(h):
    header = Path(os.environ.get("RSG_TYPE_HASHES_HEADER", ""))
    check(header.is_file(), f"RSG_TYPE_HASHES_HEADER names no file ({header}): run the test through ctest")
    ours = header_hashes(header)
    check(sorted(ours) == sorted(RSG_TYPES + STANDARD_TYPES),
          f"{header} hashes {sorted(ours)}, the gateway publishes {sorted(RSG_TYPES + STANDARD_TYPES)}")

    env = RosEnv(h.domain)
    judge = subprocess.run([env.python, str(Path(__file__).resolve().parent / "rosidl_type_hashes.py"),
                            str(h.dir / "rosidl"), str(REPO / "ros2/rsg_msgs"), "--standard", *STANDARD_TYPES],
                           env={**os.environ, **env.vars}, capture_output=True, text=True, timeout=120)
    check(judge.returncode == 0, f"rosidl failed: {judge.stderr.strip()}")
    # rosidl prints its own lines too
    theirs = dict(re.findall(r"^([\w/]+/msg/\w+) (RIHS01_[0-9a-f]{64})$", judge.stdout, re.MULTILINE))
    for name in RSG_TYPES + STANDARD_TYPES:
        check(name in theirs, f"rosidl computed no hash of {name}: {judge.stdout.strip()}")
        check(ours[name] == theirs[name], f"{name}: rsg computes {ours[name]}, rosidl {theirs[name]} "
              "(ros2/type_hashes.py or ros2/standard_msgs disagrees with REP 2011 as rosidl implements it)")
        print(f"[type_hashes_match_rosidl] {name} {ours[name]}: rosidl agrees")
    # docs/ros2.md's table of today's hashes is checked too, not trusted.
    documented = dict(re.findall(r"^\| `([\w/]+)` \| `(RIHS01_[0-9a-f]{64})` \|$",
                                 (REPO / "docs/ros2.md").read_text(), re.MULTILINE))
    check(documented == ours, f"docs/ros2.md's table of type hashes {documented} is not the build's {ours}: "
          "copy the build's (src/gateway/ros2_type_hashes.hpp) into it")


if __name__ == "__main__":
    sys.exit(main("type_hashes_match_rosidl", body))
