"""A sender stopped (SIGSTOP) for 150 ms in mid-stream, then let go: the gateway publishes every
frame, none out of sequence, none lost, and counts no restart. rsg_sim goes on from there (its
report counts a stall) rather than sending the frames due meanwhile in a burst; that bunched frames
are no forgery either, the sequence tracker's unit tests show."""

import signal
import sys
import time

from harness import check, main, read_json, wait_for_stats, free_udp_port

RATE = "1000"
SENT = 1500


def body(h):
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", RATE)
    wait_for_stats(stats, lambda s: True, "the gateway to start")

    report_path = h.dir / "sim.report.json"
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count", str(SENT),
                          "--fields", "q,time", "--report", str(report_path)])
    wait_for_stats(stats, lambda s: s["frames_received"] >= 300, "the gateway to receive the first frames")
    sim.send_signal(signal.SIGSTOP)
    time.sleep(0.15)
    sim.send_signal(signal.SIGCONT)
    check(h.wait("sim", sim, 30) == 0, "rsg_sim did not exit 0")
    report = read_json(report_path)
    check(report["sent"] == SENT and report["stalls"] >= 1, f"sim report: {report}")

    final = wait_for_stats(stats, lambda s: s["frames_received"] >= SENT, "the gateway to count every datagram")
    counts = {key: final[key] for key in ("frames_published", "out_of_sequence", "lost", "robot_restarts")}
    expected = {"frames_published": SENT, "out_of_sequence": 0, "lost": 0, "robot_restarts": 0}
    check(counts == expected, f"gateway {counts} != {expected}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("busy_sender", body))
