"""Drops, duplicates, reorders, corruptions, a robot restart and a pause: the gateway's lost /
duplicated / reordered / restart counters equal the sim's report, and the status topic shows the
link going down during the pause and up again."""

import sys

from harness import check, main, read_json, read_json_lines, wait_for, wait_for_stats, free_udp_port

RATE = "300"
# The restart and the pause are placed where no fault hits the frames around them, so that what
# the sim did is unambiguous from the receiver's side.
SIM_FAULTS = ["--drop-every", "7", "--duplicate-every", "11", "--reorder-every", "13", "--corrupt-every", "17",
              "--restart-after", "367", "--pause-after", "633", "--pause-ms", "500"]


def body(h):
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", RATE)
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    h.start("probe", [h.binary("rsg_status_probe"), "--domain", str(h.domain), "--timeout", "55"])
    # The status writer is transient-local: a matched probe prints the current status at once.
    wait_for(lambda: read_json_lines(h.output("probe")), "the status probe to match the gateway")

    report_path = h.dir / "sim.report.json"
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count", "900",
                           "--fields", "q,time", *SIM_FAULTS, "--report", str(report_path)])
    check(status == 0, f"rsg_sim exited {status}")
    report = read_json(report_path)
    check(report["restarts"] == 1 and report["pauses"] == 1, f"sim report: {report}")

    final = wait_for_stats(stats, lambda s: s["frames_received"] >= report["sent"], "the gateway to count every datagram")
    expected = {"lost": report["dropped"], "duplicated": report["duplicated"],
                "reordered": report["reordered"], "robot_restarts": report["restarts"]}
    actual = {key: final[key] for key in expected}
    check(actual == expected, f"gateway {actual} != sim {expected}")

    # Link: up while streaming, down in the pause (an extra status sample, not the 1 Hz one), up again.
    def down_and_up_again():
        history = [line["link_up"] for line in read_json_lines(h.output("probe"))]
        changes = [state for i, state in enumerate(history) if i == 0 or state != history[i - 1]]
        return any(changes[i:i + 3] == [True, False, True] for i in range(len(changes)))
    wait_for(down_and_up_again, "status samples showing the link up, down in the pause, and up again")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("sequence_and_link", body))
