"""What egress (DDS -> robot) sends is bounded (issue 39): an unpaced writer on the egress topic gets
no more than --egress-rate frames a second (plus the burst of 1/10 s) to the robot, the rest counted
egress_rate_limited and logged once; a sample that selects no field, whose frame would be byte for
byte a selection request, is never sent and is counted egress_request_like.

Before: an unpaced writer drove 115,873 frames in 5 s to the robot, and an empty selection went
out as a 14-byte selection request. The unpaced writer here is a gateway's RobotState writer fed by
rsg_sim as fast as it can send."""

import sys

from harness import UdpRelay, check, free_udp_port, main, read_json, wait_for, wait_for_stats

EGRESS_RATE = 200
BURST = EGRESS_RATE // 10  # Egress::kBurstSeconds
FLOOD = 20000


def max_in_window(times, window_s):
    """The most datagrams that arrived within any `window_s` (times sorted)."""
    most, start = 0, 0
    for end in range(len(times)):
        while times[end] - times[start] > window_s:
            start += 1
        most = max(most, end - start + 1)
    return most


def body(h):
    ingress_port, sink_port = free_udp_port(), free_udp_port()
    ingress, ingress_stats = h.gateway("ingress", "--listen", f"127.0.0.1:{ingress_port}", "--topic", "cmd",
                                       "--expected-rate", "100000")
    egress, egress_stats = h.gateway("egress", "--egress-topic", "cmd", "--send-to", f"127.0.0.1:{sink_port}",
                                     "--status-topic", "egress_status", "--egress-rate", str(EGRESS_RATE))
    sink = UdpRelay(sink_port)
    sink.start()
    try:
        wait_for_stats(ingress_stats, lambda s: s["state_readers"] >= 1, "the egress reader to match")
        wait_for_stats(egress_stats, lambda s: s["egress_writers"] >= 1, "the egress reader to see the writer")

        # 1. Empty selections: frames 1, 3, 5, 7, 9 select nothing (14 bytes, a request look-alike).
        status = h.run("sim_empty", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{ingress_port}", "--rate", "100",
                                     "--count", "10", "--every", "2:q,time"])
        check(status == 0, f"rsg_sim exited {status}")
        # Samples written before the egress reader saw the writer may miss it: judge what it took.
        counted = wait_for_stats(egress_stats, lambda s: s["egress_samples"] >= 6 and
                                 s["egress_samples"] == s["egress_frames_sent"] + s["egress_request_like"],
                                 "egress to take the samples")
        wait_for(lambda: len(sink.datagrams) >= counted["egress_frames_sent"], "the frames that carry fields")
        check(counted["egress_request_like"] >= 1 and len(sink.datagrams) == counted["egress_frames_sent"],
              f"egress counters after the empty selections: {counted}, {len(sink.datagrams)} at the robot")
        requests = [d.hex() for d in sink.datagrams if len(d) <= 14]
        check(not requests, f"egress sent selection-request look-alikes: {requests}")

        # 2. The flood: as fast as rsg_sim sends, through the ingress gateway's writer.
        before = len(sink.datagrams)
        status = h.run("sim_flood", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{ingress_port}", "--rate", "1000000",
                                     "--count", str(FLOOD), "--fields", "q,time"])
        check(status == 0, f"rsg_sim exited {status}")
        wait_for_stats(egress_stats, lambda s: s["egress_rate_limited"] > 0, "egress to limit the flood")
        # Until egress has taken what reached it: its counters still for two stats-file updates.
        previous = {}

        def settled():
            nonlocal previous
            now = read_json(egress_stats) or {}
            counters = {key: value for key, value in now.items() if key.startswith("egress_")}
            done = bool(counters) and counters == previous
            previous = counters
            return now if done else None
        final = wait_for(settled, "the egress counters to settle", interval_s=1.1)
    finally:
        sink.stop()

    flood_times = sink.times[before:]
    check(final["egress_samples"] == final["egress_frames_sent"] + final["egress_request_like"]
          + final["egress_rate_limited"] + final["egress_unencodable"], f"egress counters do not add up: {final}")
    # In any second, at most the rate plus the burst (and one for the window's edges).
    most = max_in_window(flood_times, 1.0)
    check(most <= EGRESS_RATE + BURST + 1, f"{most} frames reached the robot within one second "
                                           f"(--egress-rate {EGRESS_RATE})")
    check(len(flood_times) >= BURST, f"only {len(flood_times)} frames of the flood reached the robot")
    warnings = [line for line in (h.dir / "egress.err").read_text().splitlines() if "--egress-rate" in line]
    # Logged when it bites, then at most once per 10 s (the flood lasts less).
    check(1 <= len(warnings) <= 2, f"expected one warning about the rate limit, got {warnings}")
    check(h.stop("ingress", ingress) == 0 and h.stop("egress", egress) == 0, "a gateway did not exit 0")


if __name__ == "__main__":
    sys.exit(main("egress_limits", body))
