"""ROS 2 egress from a real ROS 2 node: an rclpy publisher of rsg_msgs/msg/RobotState (rosidl-built,
rmw_fastrtps_cpp, default QoS) on /robot1/robot_state_cmd makes rsg_gateway --ros2 --ros2-namespace
/robot1 --send-to send each message as the raw frame it describes, byte for byte what rsg_frame
encodes from the same canonical JSON (zeros for fields the frame does not select; -0.0, 1e-300 and
a uint64 time above 2^63 survive). The graph API shows the gateway's egress reader as a
subscription of rsg_msgs/msg/RobotState, reliable and volatile, with rosidl's type hash.
"""
import json
import sys
from pathlib import Path

from harness import check, main  # noqa: E402
from rclpy_common import RosEnv, graph_query, group_present, hash_hint, start_peer  # noqa: E402
from test_ros2_egress import check_egress, command_records, egress_gateway, encode  # noqa: E402


def message_of(record, member_order):
    """The RobotState message for a canonical frame: selected fields by their lowercase names."""
    message = {"packet_number": record["packet_number"], "group_select": record["group_select"],
               "data_select": record["data_select"], "group_present": group_present(record["group_select"])}
    message.update({name.lower(): value for name, value in record["fields"].items()})
    check(all(name in member_order for name in message), f"not RobotState members: {set(message) - set(member_order)}")
    return message


def body(h):
    env = RosEnv(h.domain)
    records = command_records()
    _, expected = encode(h, records)
    members = (Path(env.install) / "share/rsg_msgs/msg/RobotState.msg").read_text()
    order = [line.split()[1] for line in members.splitlines()
             if line.strip() and not line.startswith("#") and "=" not in line.split("#")[0]]
    messages = h.dir / "cmd.messages.jsonl"
    messages.write_text("".join(json.dumps(message_of(r, order)) + "\n" for r in records))

    with egress_gateway(h) as (sink, gateway, stats):
        publisher = start_peer(h, env, "publisher", "pub", "/robot1/robot_state_cmd", "rsg_msgs/msg/RobotState",
                               "--file", messages, "--timeout", 60)
        # The node publishes once its publisher matched the gateway's reader and exits 0 only when
        # that reader acknowledged every message (so it had matched the node too).
        check(h.wait("publisher", publisher, 90) == 0, "the rclpy publisher's messages were not all acknowledged")
        graph_query(h, env, "graph", "/robot1/robot_state_cmd", "--subscriptions", "--timeout", 30)
        check_egress(h, sink, expected, stats, gateway)
    readers = json.loads(h.output("graph").read_text())["subscriptions"]["/robot1/robot_state_cmd"]
    check(len(readers) == 1, f"{len(readers)} subscriptions of /robot1/robot_state_cmd in the ROS graph")
    reader = readers[0]
    want = env.type_hash("rsg_msgs", "RobotState")
    check(reader["topic_type"] == "rsg_msgs/msg/RobotState" and reader["topic_type_hash"] == want,
          f"the egress reader shows as {reader['topic_type']} {reader['topic_type_hash']}, rosidl computed {want}"
          + hash_hint(reader["topic_type_hash"]))
    check(reader["reliability"] == "RELIABLE" and reader["durability"] == "VOLATILE",
          f"the egress reader asks {reader['reliability']} {reader['durability']}; docs/ros2.md says reliable, volatile")


if __name__ == "__main__":
    sys.exit(main("rclpy_egress", body))
