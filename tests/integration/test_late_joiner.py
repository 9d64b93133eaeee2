"""A reader that joins after the robot stopped: a transient-local reader gets the states the
gateway's writer retained (its history: the last 1000), a volatile one gets none."""

import sys
from pathlib import Path

from harness import check, main, read_json_lines, wait_for_stats, free_udp_port

SENT = 1200    # more than the writer's history, so the bound is visible
HISTORY = 1000  # rsg_state_writer's keep-last depth (xml_profiles/gateway.xml)
RATE = "1000"


def body(h):
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", RATE)
    wait_for_stats(stats, lambda s: True, "the gateway to start")

    record = h.dir / "sim.record.jsonl"
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count", str(SENT),
                           "--every", "1:q,dq,time", "--every", "7:all", "--record", str(record)])
    check(status == 0, f"rsg_sim exited {status}")
    wait_for_stats(stats, lambda s: s["frames_published"] == SENT, f"the gateway to publish {SENT} frames")

    # Joins now that the stream has ended.
    here = Path(__file__).resolve().parent
    profiles = ["--profiles", str(here.parents[1] / "xml_profiles"), "--profiles", str(here / "late_joiner_profiles.xml")]
    late = h.start("late", [h.binary("rsg_echo"), "--domain", str(h.domain), "--json", *profiles,
                            "--qos", "reader_late_joiner", "--count", str(HISTORY), "--timeout", "10"])
    check(h.wait("late", late, 30) == 0, "the transient-local late joiner did not get the retained history")
    volatile = h.start("volatile", [h.binary("rsg_echo"), "--domain", str(h.domain), "--json", "--timeout", "2"])
    check(h.wait("volatile", volatile, 30) == 1, "a volatile late joiner should time out with nothing")

    sent = read_json_lines(record)
    received = read_json_lines(h.output("late"))
    check(len(received) == HISTORY, f"the late joiner got {len(received)} samples, not the history's {HISTORY}")
    check(received == sent[-HISTORY:], "the late joiner's samples are not the last frames sent, in order")
    check(read_json_lines(h.output("volatile")) == [], "the volatile late joiner printed samples")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("late_joiner", body))
