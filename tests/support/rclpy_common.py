"""What the rclpy tests share: the project's ROS 2 environment (make deps: .deps/ros2-jazzy and
.deps/ros2_ws-jazzy/install for ROS 2 Jazzy, set up by ros2/env.sh), starting rclpy_peer.py in it, and
rsg_sim's canonical JSON as the RobotState message a ROS 2 node must see. The distribution is
RSG_ROS_DISTRO's (jazzy when unset, the only one make deps installs since Kilted was retired), as for
ros2/env.sh.

The tests themselves run under any Python 3 (ctest's); only rclpy_peer.py runs in the ROS 2
environment, on the test's DDS domain (ROS_DOMAIN_ID = the gateway's --domain).
"""
import json
import os
import re
import signal
import subprocess
from pathlib import Path

from harness import check, wait_for

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
PEER = REPO / "tests" / "ros2" / "rclpy_peer.py"


class RosEnv:
    """The variables ros2/env.sh sets, read once; fails naming `make deps` when they are missing
    or when the workspace was built from other .msg files than the repository's."""

    def __init__(self, domain, distro=None):
        deps = os.environ.get("RSG_DEPS_DIR") or str(REPO / ".deps")
        self.distro = distro or os.environ.get("RSG_ROS_DISTRO") or "jazzy"
        shell = subprocess.run(["bash", "-c", f'. "{REPO}/ros2/env.sh" > /dev/null && env -0'],
                               env={**os.environ, "RSG_DEPS_DIR": deps, "RSG_ROS_DISTRO": self.distro},
                               capture_output=True)
        check(shell.returncode == 0,
              f"no ROS 2 {self.distro} environment in {deps} (the ROS 2 {self.distro} wheels and the "
              f"rsg_msgs/tf2_msgs workspace): run `make deps` ({shell.stderr.decode().strip()})")
        variables = dict(item.split("=", 1) for item in shell.stdout.decode().split("\0") if "=" in item)
        keep = ("PATH", "LD_LIBRARY_PATH", "PYTHONPATH", "AMENT_PREFIX_PATH", "CMAKE_PREFIX_PATH", "RMW_IMPLEMENTATION",
                "ROS_DISTRO", "ROS_VERSION", "ROS_PYTHON_VERSION", "_ROS_WHEELS_BOOTSTRAP_COMPLETE", "RSG_ROS2_VENV",
                "RSG_ROS2_INSTALL", "RSG_ROS_DISTRO")
        self.vars = {key: variables[key] for key in keep if key in variables}
        check(self.vars.get("ROS_DISTRO") == self.distro,
              f"ros2/env.sh set ROS_DISTRO={self.vars.get('ROS_DISTRO')} for RSG_ROS_DISTRO={self.distro}")
        self.vars["ROS_DOMAIN_ID"] = str(domain)
        self.vars["ROS_LOG_DIR"] = os.environ.get("TMPDIR", "/tmp")
        self.python = str(Path(self.vars["RSG_ROS2_VENV"]) / "bin" / "python")
        self.install = Path(self.vars["RSG_ROS2_INSTALL"])
        for name in ("RobotState.msg", "GatewayStatus.msg"):
            built = self.install / "share/rsg_msgs/msg" / name
            source = REPO / "ros2/rsg_msgs/msg" / name
            check(built.exists() and built.read_text() == source.read_text(),
                  f"{built} is not the repository's {name}: run `make deps` to rebuild the ROS 2 workspace")

        self.deps = deps
        self.domain = domain

    def argv(self, *args):
        """argv running rclpy_peer.py the way a user would: ros2/env.sh sourced, ROS_DOMAIN_ID set
        (the harness starts children with the test's own environment)."""
        return self.script_argv(PEER, *args)

    def script_argv(self, script, *args):
        """The same for another script meant for the ROS 2 environment (make bench's rate_peer.py)."""
        return ["env", f"ROS_DOMAIN_ID={self.domain}", f"RSG_DEPS_DIR={self.deps}", f"RSG_ROS_DISTRO={self.distro}",
                f"ROS_LOG_DIR={self.vars['ROS_LOG_DIR']}",
                "bash", "-c", '. "$0" && exec python "$@"', str(REPO / "ros2/env.sh"), str(script), *map(str, args)]

    def type_hash(self, package, name):
        """The RIHS01 hash rosidl's type-description generator computed for package/msg/name."""
        description = json.loads((self.install / "share" / package / "msg" / f"{name}.json").read_text())
        for entry in description["type_hashes"]:
            if entry["type_name"] == f"{package}/msg/{name}":
                return entry["hash_string"]
        raise AssertionError(f"no hash of {package}/msg/{name} in its type description")

    def standard_type_hash(self, package, name):
        """Same, for a type of the wheels (sensor_msgs, geometry_msgs) or of the workspace (tf2_msgs)."""
        for prefix in (self.install, Path(self.vars["RSG_ROS2_VENV"])):
            path = prefix / "share" / package / "msg" / f"{name}.json"
            if path.exists():
                for entry in json.loads(path.read_text())["type_hashes"]:
                    if entry["type_name"] == f"{package}/msg/{name}":
                        return entry["hash_string"]
        raise AssertionError(f"no type description of {package}/msg/{name}")


def hash_hint(announced):
    """Why a gateway announces no type hash, for the failure message."""
    if announced != "INVALID":
        return ""
    return (" (none announced: this rsg_gateway was built without the header of "
            "cmake/rsg_ros2_type_hashes.cmake, or its type is not listed there)")


# Every ROS 2 writer of a gateway run with --ros2 and the three standard topics, by topic.
GATEWAY_ROS2_TYPES = {"/robot_state": ("rsg_msgs", "RobotState"), "/gateway_status": ("rsg_msgs", "GatewayStatus"),
                      "/joint_states": ("sensor_msgs", "JointState"), "/tf": ("tf2_msgs", "TFMessage"),
                      "/external_wrench": ("geometry_msgs", "WrenchStamped")}


def check_rosidl_type_hashes(env):
    """A real rclpy node's view of the ROS graph on env's domain: one publisher on each topic of
    GATEWAY_ROS2_TYPES, announcing the RIHS01 hash rosidl computes for its type. Returns how many."""
    graph = subprocess.run(env.argv("graph", *GATEWAY_ROS2_TYPES, "--wait-publishers", 1, "--timeout", 30),
                           capture_output=True, text=True, timeout=90)
    check(graph.returncode == 0, f"the rclpy graph query failed: {graph.stderr[-1000:]}")
    publishers = json.loads(graph.stdout.strip().splitlines()[-1])["publishers"]
    for topic, (package, name) in GATEWAY_ROS2_TYPES.items():
        check(len(publishers[topic]) == 1, f"{topic}: {len(publishers[topic])} publishers in the ROS graph")
        want = env.type_hash(package, name) if package == "rsg_msgs" else env.standard_type_hash(package, name)
        got = publishers[topic][0]["topic_type_hash"]
        check(got == want, f"{topic} ({package}/msg/{name}) announces type hash {got}, rosidl computed {want}")
    return len(GATEWAY_ROS2_TYPES)


def start_peer(h, env, label, *args):
    return h.start(label, env.argv(*args))


def graph_query(h, env, label, *args):
    """Runs rclpy_peer's graph query to its end; its JSON is then in h.output(label). A query that
    crashes (SIGSEGV: its rclpy / Fast DDS tearing down, seen once after a complete answer) is the
    peer's failure, not the gateway's: it is asked once more, and the test says so."""
    for attempt in (1, 2):
        status = h.wait(label, start_peer(h, env, label, "graph", *args), 60)
        if status == 0:
            return
        check(status == -signal.SIGSEGV and attempt == 1, f"the graph query failed (exit {status})")
        print(f"[{h.name}] the graph query crashed (exit {status}): its rclpy, not the gateway; asked again",
              flush=True)


def wait_peer_matched(h, label, count=1):
    """Both sides of discovery: the node's own matched event (rclpy_peer prints it)."""
    err = h.dir / f"{label}.err"
    wait_for(lambda: err.exists() and any(line.startswith("matched ") and int(line.split()[1]) >= count
                                          for line in err.read_text(errors="replace").splitlines()),
             f"{label}'s ROS 2 subscription or publisher to match")


def error_flag_names():
    """kErrorFlagNames of include/rsg/wire/error_flags.hpp: canonical JSON lists the set bits of
    current_errors and last_motion_errors by name, the message carries the uint64."""
    header = (REPO / "include/rsg/wire/error_flags.hpp").read_text()
    body = header[header.index("kErrorFlagNames"):]
    return re.findall(r'"([a-z0-9_]+)"', body[:body.index("};")])


ERROR_FLAGS = error_flag_names()
BITMASK_FIELDS = ("current_errors", "last_motion_errors")


def group_present(group_select):
    return [bool(group_select >> group & 1) for group in range(6)]


def expected_message(sent, member_order):
    """The rsg_msgs/RobotState a frame of canonical JSON must arrive as: header members, then every
    field member in field-table order (bit g*8+b of data_select) with the frame's value when present
    and zeros when not (the .msg says so). `member_order` is the message's member names in order."""
    fields = {name.lower(): value for name, value in sent["fields"].items()}
    for name in BITMASK_FIELDS:
        if name in fields:
            fields[name] = sum(1 << ERROR_FLAGS.index(flag) for flag in fields[name])
    message = {"packet_number": sent["packet_number"], "group_select": sent["group_select"],
               "data_select": sent["data_select"], "group_present": group_present(sent["group_select"])}
    header = list(message)
    check(member_order[:len(header)] == header, f"RobotState starts with {member_order[:len(header)]}")
    for index, name in enumerate(member_order[len(header):]):
        present = sent["data_select"][index // 8] >> (index % 8) & 1
        message[name] = fields.pop(name) if present else None  # None: zeros, shape from the message
    check(not fields, f"frame fields that are no RobotState member: {sorted(fields)}")
    return message


def same_message(expected, got):
    """Member by member; absent fields must be all zeros. Returns the first difference or ''."""
    if list(expected) != list(got):
        return f"members {list(got)} instead of {list(expected)}"
    for name, want in expected.items():
        value = got[name]
        if want is None:
            zero = all(item == 0 for item in value) if isinstance(value, list) else value == 0
            if not zero:
                return f"{name} = {value} where the frame had no such field (must be 0)"
        elif value != want:
            return f"{name} = {value}, sent {want}"
    return ""


def read_messages(h, label):
    path = h.output(label)
    text = path.read_text() if path.exists() else ""
    return [json.loads(line) for line in text.split("\n")[:-1] if line.strip()]


def check_in_order(label, sent, got, member_order):
    """Every message equals a sent frame, in the order sent; returns the positions matched."""
    expected = [expected_message(frame, member_order) for frame in sent]
    positions, position = [], 0
    for index, message in enumerate(got):
        while position < len(expected) and same_message(expected[position], message):
            position += 1
        if position == len(expected):
            closest = min(expected, key=lambda e: abs(e["packet_number"] - message["packet_number"]))
            check(False, f"{label}: message {index} is no frame sent after the previous one: "
                         f"{same_message(closest, message)}")
        positions.append(position)
        position += 1
    return positions
