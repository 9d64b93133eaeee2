"""The secure deployment docs/security.md shows, end to end: rsg_gateway and rsg_echo with the test PKI's
participant profiles. The authenticated, permitted reader gets every frame exactly; a plain
rsg_echo on the same domain, started first, is never matched and prints nothing."""

import sys

from harness import check, main, read_json, read_json_lines, wait_for_stats, wait_reader_matched, free_udp_port

COUNT = 200
RATE = "200"


def body(h):
    profiles = h.secure_profiles()
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--profiles", str(profiles),
                               "--participant-profile", "rsg_secure_gateway")
    wait_for_stats(stats, lambda s: True, "the secure gateway to start")

    echo = [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "robot_state", "--json"]
    plain = h.start("plain_echo", echo)
    secure = h.start("secure_echo", [*echo, "--profiles", str(profiles), "--participant-profile",
                                     "rsg_secure_reader", "--count", str(COUNT), "--timeout", "45"])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, "the secure reader to match the gateway's writer",
                   timeout_s=40)
    wait_reader_matched(h, "secure_echo", "rsg_echo")  # a volatile reader misses what comes before it

    record = h.dir / "sim.record.jsonl"
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count", str(COUNT),
                           "--record", str(record)])
    check(status == 0, f"rsg_sim exited {status}")
    check(h.wait("secure_echo", secure, 45) == 0, "the secure reader did not receive every sample")
    sent = read_json_lines(record)
    received = read_json_lines(h.output("secure_echo"))
    check(len(sent) == COUNT and received == sent,
          f"the secure reader got {len(received)} samples for {len(sent)} frames, or other values")

    # The plain reader started before the secure one, which has everything by now.
    check(read_json(stats)["state_readers"] == 1, f"the gateway matched other readers: {read_json(stats)}")
    check(h.stop("plain_echo", plain) == 0, "the plain rsg_echo did not exit 0 on SIGTERM")
    check(h.output("plain_echo").read_text() == "", "the plain, unauthenticated rsg_echo received samples")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("secure_gateway", body))
