"""Secure egress: only an identity granted rsg_egress can make the gateway send frames to the
robot. A commander (permissions_commander.xml.in) writes samples; every one leaves the gateway
as a frame with a valid CRC. The reader identity is refused a writer on that topic."""

import subprocess
import sys
import zlib

from harness import UdpRelay, check, main, read_json, read_json_lines, wait_for, wait_for_stats, free_udp_port

SAMPLES = 20


def probe(h, label, profiles, identity):
    """rsg_secure_probe writing SAMPLES samples on rsg_egress as `identity`; it stays in the domain
    until its standard input closes."""
    return h.start(label, [h.binary("rsg_secure_probe"), "publish", "--profiles", str(profiles / "rsg_secure_profiles.xml"),
                           "--profile", f"rsg_secure_{identity}", "--domain", str(h.domain), "--topic", "rsg_egress",
                           "--samples", str(SAMPLES), "--wait-for-reader"], stdin=subprocess.PIPE)


def ready_event(h, label):
    events = wait_for(lambda: [e for e in read_json_lines(h.output(label)) if e["event"] == "ready"],
                      f"{label} to set up", timeout_s=40)
    return events[0]


def has_valid_crc(frame):
    return len(frame) >= 14 and zlib.crc32(frame[:-4]) == int.from_bytes(frame[-4:], "little")


def body(h):
    profiles = h.secure_profiles()
    robot_port = free_udp_port()
    robot = UdpRelay(robot_port)
    robot.start()
    try:
        gateway, stats = h.gateway("gateway", "--egress-topic", "rsg_egress", "--send-to", f"127.0.0.1:{robot_port}",
                                   "--profiles", str(profiles), "--participant-profile", "rsg_secure_gateway")
        wait_for_stats(stats, lambda s: True, "the secure gateway to start")

        commander = probe(h, "commander", profiles, "commander")
        check(ready_event(h, "commander")["endpoint_created"], "the commander was refused its rsg_egress writer")
        wait_for(lambda: len(robot.datagrams) >= SAMPLES, f"{SAMPLES} frames at the robot (have {len(robot.datagrams)})",
                 timeout_s=40)

        intruder = probe(h, "reader_as_commander", profiles, "reader")
        check(not ready_event(h, "reader_as_commander")["endpoint_created"],
              "the reader identity was allowed to write rsg_egress")
        for process in (commander, intruder):
            process.stdin.close()
            h.wait("probe", process)
    finally:
        robot.stop()

    check(len(robot.datagrams) == SAMPLES, f"the robot got {len(robot.datagrams)} frames for {SAMPLES} samples")
    check(all(map(has_valid_crc, robot.datagrams)), "a frame sent to the robot has a bad CRC")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    final = read_json(stats)
    check((final["egress_samples"], final["egress_frames_sent"]) == (SAMPLES, SAMPLES),
          f"the gateway took {final['egress_samples']} samples and sent {final['egress_frames_sent']} frames")


if __name__ == "__main__":
    sys.exit(main("secure_egress", body))
