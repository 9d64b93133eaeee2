"""Selection request: the gateway asks for group 2 and the robot complies.

1. Without --robot the request goes to wherever frames come from: the sim starts with every
   group, honours the request on its sending socket, and every later frame carries group 2 only.
2. With --robot the request goes out at start-up, byte for byte as docs/protocol.md defines it.
"""

import socket
import struct
import sys
import zlib

from harness import check, main, read_json, read_json_lines, wait_for_stats, wait_reader_matched, free_udp_port

COUNT = 600
RATE = "300"
GROUP_2 = {"group_select": 0b100, "data_select": [0, 0, 0xFF, 0, 0, 0]}


def expected_request(packet_number, group_select, data_select):
    header = struct.pack("<BHB6B", 0x30 | packet_number, 0, group_select, *data_select)
    return header + struct.pack("<I", zlib.crc32(header))


def sim_follows_the_request(h):
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--request-groups", "2",
                               "--expected-rate", RATE)
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    echo = h.start("echo", [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "robot_state",
                            "--json", "--count", str(COUNT), "--timeout", "45"])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, "rsg_echo's reader to match the gateway's writer")
    wait_reader_matched(h, "echo", "rsg_echo")

    report_path = h.dir / "sim.report.json"
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count", str(COUNT),
                           "--report", str(report_path)])
    check(status == 0, f"rsg_sim exited {status}")
    check(h.wait("echo", echo, 45) == 0, "rsg_echo did not receive every frame")
    check(read_json(report_path)["selection_requests"] >= 1, "the sim applied no selection request")

    samples = read_json_lines(h.output("echo"))
    selections = [{"group_select": s["group_select"], "data_select": s["data_select"]} for s in samples]
    check(selections[0] != GROUP_2, "the first frame, sent before any request, should carry the sim's default")
    first = selections.index(GROUP_2) if GROUP_2 in selections else None
    check(first is not None, "no frame ever carried group 2 alone")
    later = [i for i in range(first, len(selections)) if selections[i] != GROUP_2]
    check(not later, f"frame {later[0] if later else -1} after the switch carries {selections[later[0]] if later else ''}")
    check(all(set(s["fields"]) == {"delbow_c", "ddelbow_c", "tau_J", "tau_J_d", "dtau_J", "q", "q_d", "dq"}
              for s in samples[first:]), "frames after the switch carry other fields than group 2's")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


def request_at_start_up(h):
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as robot:
        robot.bind(("127.0.0.1", 0))
        robot.settimeout(20)
        robot_port = robot.getsockname()[1]
        listen_port = free_udp_port()
        gateway, _ = h.gateway("gateway_robot", "--listen", f"127.0.0.1:{listen_port}", "--robot",
                               f"127.0.0.1:{robot_port}", "--request-groups", "2")
        datagram, sender = robot.recvfrom(65536)
        check(sender[1] == listen_port, f"the request came from port {sender[1]}, not the listening {listen_port}")
        check(datagram == expected_request(0, GROUP_2["group_select"], GROUP_2["data_select"]),
              f"request bytes {datagram.hex()} differ from docs/protocol.md's")
        check(h.stop("gateway_robot", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


def body(h):
    sim_follows_the_request(h)
    request_at_start_up(h)


if __name__ == "__main__":
    sys.exit(main("selection_request", body))
