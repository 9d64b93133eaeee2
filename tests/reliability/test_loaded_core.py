"""Zero loss at 1 kHz with the second core taken by a busy loop.

A process spinning on one CPU (pinned to the last one) leaves the gateway, the simulator and a
reliable logger to share what is left of a 2-core machine for a 10 s stream.

Pins that the gateway loses nothing (lost = 0, every datagram received and every frame published)
and the reliable logger gets every frame exactly once, in order, with the values sent.
"""

import os
import sys

from reliability import (BusyLoop, check, check_counters, check_delivered_exactly_once, main, run_sim,
                         settled_stats, start_gateway, start_logger, stop_child, wait_for_readers)
from harness import wait_reader_matched  # noqa: E402

RATE_HZ = 1000
COUNT = 10 * RATE_HZ


def body(h):
    gateway, stats, port = start_gateway(h, RATE_HZ)
    logger = start_logger(h, "logger")
    wait_for_readers(stats, 1)
    wait_reader_matched(h, "logger", "rsg_echo")

    with BusyLoop(h, cpu=max(os.sched_getaffinity(0))):
        report, record, _ = run_sim(h, port, RATE_HZ, COUNT, "--fields", "q,time")
        check_delivered_exactly_once(h, "logger", record)
    check_counters(settled_stats(stats, report), report)
    check(stop_child(h, "logger", logger) == 0, "rsg_echo did not exit 0")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("loaded_core", body))
