"""sim -> gateway -> echo: every valid frame arrives exactly once, with the values the sim sent."""

import sys

from harness import check, main, read_json, read_json_lines, wait_for_stats, wait_reader_matched, free_udp_port

COUNT = 1000
RATE = "500"


def body(h):
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", RATE)
    wait_for_stats(stats, lambda s: True, "the gateway to start")

    echo = h.start("echo", [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "robot_state",
                            "--json", "--count", str(COUNT), "--timeout", "45"])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, "rsg_echo's reader to match the gateway's writer")
    wait_reader_matched(h, "echo", "rsg_echo")

    record, report = h.dir / "sim.record.jsonl", h.dir / "sim.report.json"
    # Changing selections: joints every frame, group 0 every third, everything every tenth.
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count", str(COUNT),
                           "--every", "1:q,dq,time", "--every", "3:g0", "--every", "10:all",
                           "--record", str(record), "--report", str(report)])
    check(status == 0, f"rsg_sim exited {status}")
    check(h.wait("echo", echo, 45) == 0, "rsg_echo did not receive every sample")

    sent = read_json_lines(record)
    received = read_json_lines(h.output("echo"))
    check(len(sent) == COUNT, f"the sim recorded {len(sent)} frames, not {COUNT}")
    check(len(received) == len(sent), f"echo printed {len(received)} samples for {len(sent)} frames")
    for index, (expected, actual) in enumerate(zip(sent, received)):
        check(actual == expected, f"sample {index} differs from the frame sent:\n  sent {expected}\n  got  {actual}")

    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    final = read_json(stats)
    check(final["frames_received"] == COUNT, f"gateway received {final['frames_received']}")
    check(final["frames_published"] == COUNT, f"gateway published {final['frames_published']}")
    check(sum(final["invalid"].values()) == 0, f"gateway rejected frames: {final['invalid']}")
    check((final["lost"], final["duplicated"], final["reordered"]) == (0, 0, 0), f"sequence counters: {final}")


if __name__ == "__main__":
    sys.exit(main("sim_to_echo", body))
