"""Robot silent, then back, then rebooted: what a real-time reader and the status topic see.

The simulator streams at 1 kHz, goes silent for 500 ms after frame 1000, and reboots (time and
packet number back to 0) after frame 2000. rsg_deadline_probe timestamps every RobotState arrival
(reader_realtime: best effort, 100 ms deadline), every deadline miss and every status sample.

Pins that
  * a reader_realtime reader is told of the silence: on_requested_deadline_missed fires after the
    last sample before the pause and before the first one after it;
  * the status topic reports the link down within 100 ms of the last frame (the requirement;
    asserted with the CI margin of reliability.py, the measured value printed) and up again after;
  * the reboot is counted as one robot restart, and as nothing else: no frame reordered,
    duplicated or lost (the gateway's counters equal the simulator's report).
"""

import sys

from reliability import (DeadlineProbe, check, check_counters, log, main, measured, run_sim, settled_stats,
                         start_gateway, wait_for, wait_for_readers)

RATE_HZ = 1000
PAUSE_AFTER, PAUSE_MS, RESTART_AFTER, COUNT = 1000, 500, 2000, 3000
LINK_DOWN_REQUIREMENT_S = 0.100


def silence(samples):
    """The last sample before the longest gap between arrivals, and the first one after it."""
    gaps = [(later["t"] - earlier["t"], earlier, later) for earlier, later in zip(samples, samples[1:])]
    _, before, after = max(gaps, key=lambda gap: gap[0])
    return before, after


def body(h):
    gateway, stats, port = start_gateway(h, RATE_HZ)
    probe = DeadlineProbe(h)
    probe.wait_for_status()
    wait_for_readers(stats, 1)

    report, _, _ = run_sim(h, port, RATE_HZ, COUNT, "--fields", "q,time", "--pause-after", str(PAUSE_AFTER),
                           "--pause-ms", str(PAUSE_MS), "--restart-after", str(RESTART_AFTER))
    check(report["pauses"] == 1 and report["restarts"] == 1, f"simulator report: {report}")

    # The reboot: one restart, nothing reordered (checked first: the probe needs the final status).
    # The simulator reboots without a pause, so its first frames are out_of_sequence until the old
    # stream has been silent for the link's silence limit (10 ms at 1 kHz: about 8 frames, fewer if the
    # simulator stalled there).
    final = settled_stats(stats, report)
    check(final["out_of_sequence"] <= 50, f"frames held back after the reboot: {final['out_of_sequence']}")
    check_counters(final, report, out_of_sequence=final["out_of_sequence"])
    wait_for(lambda: any(s["robot_restarts"] == 1 for s in probe.events("status")),
             "a status sample counting the restart")

    before, after = silence(probe.events("sample"))
    log(h, f"MEASURED silence seen by the reader: {(after['t'] - before['t']) * 1000:.0f} ms "
           f"(the simulator paused {PAUSE_MS} ms)")
    check(after["time"] - before["time"] >= PAUSE_MS, f"the longest gap is not the pause: {before} -> {after}")

    misses = [m for m in probe.events("deadline_missed") if before["t"] < m["t"] < after["t"]]
    check(misses, "no requested_deadline_missed during the robot's silence")
    log(h, f"MEASURED first deadline miss {(misses[0]['t'] - before['t']) * 1000:.1f} ms after the last sample "
           f"(deadline 100 ms), {len(misses)} miss(es) in the silence")

    changes = [c for c in probe.link_changes() if c["t"] > before["t"]]
    check(changes and not changes[0]["link_up"], f"no link-down status after the last frame: {changes[:3]}")
    down = changes[0]
    measured(h, "link-down detection (last sample -> link-down status)", down["t"] - before["t"],
             LINK_DOWN_REQUIREMENT_S)
    check(len(changes) > 1 and changes[1]["link_up"], "no link-up status after the silence")
    log(h, f"MEASURED link-up status {(changes[1]['t'] - after['t']) * 1000:+.1f} ms from the first sample after "
           f"the silence")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("robot_silence", body))
