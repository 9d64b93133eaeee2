"""Gateway killed with SIGKILL mid-stream and restarted on the same port: readers resume.

The simulator streams at 1 kHz throughout. The gateway is killed (no clean-up of any kind: its
Fast DDS shared-memory segments stay in /dev/shm) and a new one is started at once, without
`fastdds shm clean`. A reader_realtime_udp reader (rsg_deadline_probe, timestamps) and a reliable
logger (rsg_echo --json) keep running across the restart; neither uses data-sharing, which a
SIGKILLed writer can leave locked (see the probe's comment below).

Pins that
  * the new gateway starts despite the dead one's shared memory, and the readers get samples
    again within 2 s of its start (the requirement; measured from the moment the test starts it to
    the first sample the probe timestamps, asserted with the CI margin of reliability.py);
  * the reliable logger resumes too, and what it got is exactly the frames sent, in two unbroken
    runs (before the kill, after the restart) with only the outage between them.
"""

import signal
import sys

from reliability import (DeadlineProbe, check, fastdds_shm_segments, log, main, measured, monotonic,
                         read_json_lines, start_gateway, start_logger, stop_child, wait_for, wait_for_readers)
from harness import wait_reader_matched  # noqa: E402

RATE_HZ = 1000
COUNT = 8000  # 8 s: the kill comes after ~2 s, so the restarted gateway streams for several seconds
RESUME_REQUIREMENT_S = 2.0


def unbroken_runs(received, record):
    """Checks each received sample against the frame of the same `time` (unique at 1 kHz) in the
    record; returns the runs of consecutive frames the samples form, as (first, last) indices."""
    index_of = {frame["fields"]["time"]: i for i, frame in enumerate(record)}
    runs = []
    for sample in received:
        position = index_of.get(sample["fields"]["time"])
        check(position is not None and record[position] == sample, f"a sample that was never sent: {sample}")
        if runs and position == runs[-1][1] + 1:
            runs[-1] = (runs[-1][0], position)
        else:
            runs.append((position, position))
    return runs


def body(h):
    shm_before_gateway = set(fastdds_shm_segments())
    gateway, stats, port = start_gateway(h, RATE_HZ)
    # Not data-sharing: a SIGKILL while the gateway notifies a data-sharing reader leaves that
    # reader's notification mutex locked, and Fast DDS 2.9.1 then throws in the reader and in the
    # next gateway (docs/operating.md). What this test pins is the restart.
    probe = DeadlineProbe(h, qos="reader_realtime_udp")
    logger = start_logger(h, "logger")
    wait_for_readers(stats, 2)
    wait_reader_matched(h, "logger", "rsg_echo")

    record = h.dir / "sim.record.jsonl"
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", str(RATE_HZ),
                          "--count", str(COUNT), "--fields", "q,time", "--record", str(record)])
    wait_for(lambda: len(probe.events("sample")) >= 2 * RATE_HZ, "2 s of samples before the kill")

    gateway.send_signal(signal.SIGKILL)
    h.wait("gateway", gateway)
    leftovers = set(fastdds_shm_segments()) - shm_before_gateway
    log(h, f"the killed gateway left {len(leftovers)} Fast DDS files in /dev/shm; not cleaned")

    restart_time = monotonic()
    restarted, restarted_stats, _ = start_gateway(h, RATE_HZ, port=port, label="gateway_restarted")
    first_after = wait_for(lambda: [s for s in probe.events("sample") if s["t"] > restart_time],
                           "the probe to get a sample from the restarted gateway")[0]
    last_before = [s for s in probe.events("sample") if s["t"] < restart_time][-1]
    measured(h, "resume after restart (new gateway started -> first sample)", first_after["t"] - restart_time,
             RESUME_REQUIREMENT_S)
    log(h, f"MEASURED reader gap across the kill: {(first_after['t'] - last_before['t']) * 1000:.0f} ms")

    check(h.wait("sim", sim, 30) == 0, "rsg_sim failed")
    sent = read_json_lines(record)
    wait_for(lambda: read_json_lines(h.output("logger"))[-1:] == sent[-1:], "the logger to get the last frame")
    runs = unbroken_runs(read_json_lines(h.output("logger")), sent)
    check(len(runs) == 2, f"the logger got frames {runs}: not 2 unbroken runs (before the kill, after the restart)")
    log(h, f"the logger got frames {runs[0][0]}..{runs[0][1]} before the kill and {runs[1][0]}..{runs[1][1]} after, "
           f"all unchanged; frames {runs[0][1] + 1}..{runs[1][0] - 1} were sent while no gateway listened")

    check(stop_child(h, "logger", logger) == 0, "rsg_echo did not exit 0")
    check(h.stop("gateway_restarted", restarted) == 0, "the restarted gateway did not exit 0 on SIGTERM")
    check(restarted_stats.exists(), "the restarted gateway wrote no stats")


if __name__ == "__main__":
    sys.exit(main("gateway_restart", body))
