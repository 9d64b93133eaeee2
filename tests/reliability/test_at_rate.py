"""At rate: 100,000 frames at 5 kHz, 5 % of them corrupted across all seven spec categories, through
the real processes (rsg_sim -> rsg_gateway -> a reliable rsg_echo --json logger).

Pins that, at five times the robot's nominal rate and with a steady stream of invalid input:
  * the gateway does not crash and publishes no invalid frame;
  * its counters (stats file and status topic) equal what the simulator injected, category by
    category, with nothing lost, duplicated or reordered (a corrupted frame is invalid, not also lost);
  * the reliable reader gets every valid frame exactly once, in order, with the values sent.

A small selection (q, robot_mode, time: 79-byte datagrams) keeps the UDP leg and the JSON
comparison cheap enough for a 2-core CI machine; the DDS sample is the full RobotState either way.
At 5 kHz `time` repeats (5 frames share a millisecond): exactly what the sequence tracker must
handle, and why delivery is checked line by line against the simulator's record, not by time.
"""

import sys

from reliability import (check, check_counters, check_delivered_exactly_once, log, main, read_json_lines,
                         run_sim, settled_stats, start_gateway, start_logger, stop_child, wait_for,
                         wait_for_readers)
from harness import wait_reader_matched  # noqa: E402

RATE_HZ = 5000
COUNT = 100_000
SELECTION = ["--fields", "q,robot_mode,time"]


def body(h):
    gateway, stats, port = start_gateway(h, RATE_HZ)
    h.start("status_probe", [h.binary("rsg_status_probe"), "--domain", str(h.domain), "--timeout", "80"])
    logger = start_logger(h, "logger", timeout_s=60)
    wait_for_readers(stats, 1)
    wait_reader_matched(h, "logger", "rsg_echo")

    report, record, seconds = run_sim(h, port, RATE_HZ, COUNT, *SELECTION, "--corrupt", "0.05", "--seed", "5000")
    log(h, f"MEASURED sent {report['sent']} datagrams in {seconds:.1f} s ({report['sent'] / seconds:.0f}/s), "
           f"{sum(report['invalid'].values())} invalid: {report['invalid']}")
    check(all(count > 0 for count in report["invalid"].values()),
          f"the simulator did not corrupt frames in every category: {report['invalid']}")

    delivered = check_delivered_exactly_once(h, "logger", record)
    log(h, f"the reliable reader got all {delivered} valid frames exactly once")
    check(gateway.poll() is None, f"the gateway exited ({gateway.returncode}) under load")

    check_counters(settled_stats(stats, report), report)
    status = wait_for(lambda: [s for s in read_json_lines(h.output("status_probe"))
                               if s["frames_received"] >= report["sent"]],
                      "a status sample counting every datagram")[0]
    check_counters(status, report, "status topic")

    check(stop_child(h, "logger", logger) == 0, "rsg_echo did not exit 0")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("at_rate", body))
