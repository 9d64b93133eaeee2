"""A stalled reader and a killed reader do not slow the gateway or starve the other readers.

Three reliable loggers (rsg_echo --json, reader_logger) and a real-time probe read a 1 kHz stream.
Mid-stream one logger is frozen with SIGSTOP for 4 s of stream (then resumed with SIGCONT) and
another is killed with SIGKILL (its Fast DDS resources are left behind, as after a crash).

Pins that
  * the witness logger still gets every frame exactly once, in order, with the values sent;
  * the gateway does not block on the stalled or dead reader: it publishes every valid frame and
    loses none (counters equal the simulator's report), and the rate it reports on the status
    topic while the reader is frozen stays the stream's rate (each 1 s status sample within 10 %
    of 1 kHz: a writer that blocked on the frozen reader would hold back every frame; momentary
    link-down samples, rate 0 by definition, are counted and not judged);
  * the frozen logger is still alive and exits cleanly once resumed.
"""

import signal
import sys

from reliability import (DeadlineProbe, check, check_counters, check_delivered_exactly_once, log, logged_samples,
                         main, monotonic, read_json, settled_stats, start_gateway, start_logger, stop_child,
                         wait_for, wait_for_readers)
from harness import wait_reader_matched  # noqa: E402

RATE_HZ = 1000
COUNT = 9000
STALL_FRAMES = 4 * RATE_HZ
RATE_TOLERANCE = 0.10


def body(h):
    gateway, stats, port = start_gateway(h, RATE_HZ)
    probe = DeadlineProbe(h)
    witness, frozen, doomed = (start_logger(h, label) for label in ("witness", "frozen", "killed"))
    wait_for_readers(stats, 4)
    for label in ("witness", "frozen", "killed"):
        wait_reader_matched(h, label, "rsg_echo")

    record, report_path = h.dir / "sim.record.jsonl", h.dir / "sim.report.json"
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", str(RATE_HZ),
                          "--count", str(COUNT), "--fields", "q,time", "--record", str(record),
                          "--report", str(report_path)])
    wait_for(lambda: len(logged_samples(h, "witness")) >= RATE_HZ, "1 s of stream before the faults")

    frozen.send_signal(signal.SIGSTOP)
    doomed.send_signal(signal.SIGKILL)
    stall_start, witnessed = monotonic(), len(logged_samples(h, "witness"))
    wait_for(lambda: len(logged_samples(h, "witness")) >= witnessed + STALL_FRAMES,
             f"the witness to get {STALL_FRAMES} more frames while a reader is frozen")
    stall_end = monotonic()
    frozen.send_signal(signal.SIGCONT)
    log(h, f"a reader was frozen for {stall_end - stall_start:.1f} s, another killed")

    check(h.wait("sim", sim, 30) == 0, "rsg_sim failed")
    report = read_json(report_path)
    check_delivered_exactly_once(h, "witness", record)
    check_counters(settled_stats(stats, report), report)

    # Status samples published entirely within the stall (each covers the second before it). A
    # link-down sample says rate 0 by definition (10 ms without a frame: a loaded 2-core host can
    # deschedule the robot or the gateway that long by itself), so it is counted, not judged; a
    # writer blocked on the frozen reader would hold back every frame and drop the periodic rate.
    during = [s for s in probe.events("status") if stall_start + 1.0 < s["t"] < stall_end]
    rates = [s["rate_hz"] for s in during if s["link_up"]]
    log(h, f"MEASURED gateway rate while a reader was frozen: {rates} Hz; "
           f"link-down samples: {sum(1 for s in during if not s['link_up'])}")
    check(len(rates) >= 2, f"only {len(rates)} status samples during the stall")
    check(all(abs(rate - RATE_HZ) <= RATE_TOLERANCE * RATE_HZ for rate in rates),
          f"the gateway's rate left {RATE_HZ} Hz +- {RATE_TOLERANCE:.0%} while a reader was frozen: {rates}")

    log(h, f"the frozen reader got {len(logged_samples(h, 'frozen'))} of {report['valid']} frames")
    check(stop_child(h, "frozen", frozen) == 0, "the resumed reader did not exit 0 on SIGTERM")
    check(stop_child(h, "witness", witness) == 0, "the witness did not exit 0 on SIGTERM")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("slow_readers", body))
