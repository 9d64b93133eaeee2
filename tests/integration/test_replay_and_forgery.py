"""An attacker on the robot's network, sending from the allowed address (issue 39): 100 frames of
an earlier capture replayed and 1,000 forged frames interleaved with the robot's 1 kHz stream. The
gateway publishes the robot's stream alone, in order, and counts the others out_of_sequence (not
lost, not robot restarts: docs/operating.md, "Frames that do not continue the stream"); a reliable
reader gets exactly the frames the robot sent, and the 50 Hz rate topic stays at 50 Hz.

Before: lost +400 and robot_restarts +100 for the replay, lost +9,000 and restarts +999 for the
interleave, consumers saw `time` go backwards 1,099 times and the 50 Hz topic emitted ~2,000
samples a second."""

import random
import socket
import struct
import sys
import time
import zlib

from harness import (check, free_udp_port, main, paced_count, read_json, read_json_lines, realtime_prefix, wait_for,
                     wait_for_stats, wait_reader_matched)

RATE = 1000
COUNT = 3000  # 3 s of the robot's stream
REPLAYED = 100
FORGED = 1000
RATE_HZ = 50
FORGED_Q = 666.0  # in every forged frame's q, so that a reader can tell one


def forged_frame(rng, newest_ms):
    """A valid frame (q and time, CRC right) with any packet number and a time the robot's stream
    cannot have next: in the past by more than --restart-threshold-ms, or far in the future."""
    past = rng.random() < 0.5
    robot_time = rng.randrange(0, max(1, newest_ms - 200)) if past else newest_ms + 10_000 + rng.randrange(10**9)
    data = struct.pack("<7d", *([FORGED_Q] * 7)) + struct.pack("<Q", robot_time)
    # q is field 21 (group 2, bit 5), time field 43 (group 5, bit 3): docs/protocol.md.
    selection = bytes([0b100100, 0, 0, 0x20, 0, 0, 0x08])  # group_select, then data_select[0..5]
    header = bytes([0x30 | rng.randrange(16)]) + struct.pack("<H", len(data)) + selection
    body = header + data
    return body + struct.pack("<I", zlib.crc32(body))


def body(h):
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--allow-from", "127.0.0.1",
                               "--expected-rate", str(RATE), "--rate-topic", f"robot_state_slow:{RATE_HZ}")
    wait_for_stats(stats, lambda s: True, "the gateway to start")

    # The capture the attacker replays: the robot's first frames (time 0..99 ms), sent elsewhere.
    capture = h.dir / "earlier.pcap"
    status = h.run("capture", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{free_udp_port()}", "--rate", str(RATE),
                               "--count", str(REPLAYED), "--fields", "q,time", "--pcap", str(capture)])
    check(status == 0, f"rsg_sim (capture) exited {status}")

    full = h.start("full", [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "robot_state", "--json",
                            "--qos", "reader_logger", "--timeout", "40"])
    slow = h.start("slow", [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "robot_state_slow",
                            "--json", "--qos", "reader_logger", "--timeout", "40"])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, "the reader to match the gateway")
    wait_reader_matched(h, "full", "rsg_echo")
    wait_reader_matched(h, "slow", "rsg_echo")

    record, report_path = h.dir / "robot.record.jsonl", h.dir / "robot.report.json"
    # The robot streams on time (SCHED_FIFO when allowed): a stall of its own longer than the silence
    # limit is exactly when a replayed frame may start a new sequence (docs/operating.md).
    robot = h.start("robot", [*realtime_prefix(), h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", str(RATE), "--count",
                              str(COUNT), "--fields", "q,time", "--record", str(record), "--report", str(report_path)])
    # Once the robot's time is well past the capture's, and while it streams: the replay, then the forger.
    wait_for_stats(stats, lambda s: s["frames_published"] >= 500, "the robot's stream to be under way")
    status = h.run("replay", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--replay", str(capture)])
    check(status == 0, f"rsg_sim --replay exited {status}")
    rng = random.Random(39)
    forger = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    started = time.monotonic()
    newest_ms = 0
    for i in range(FORGED):
        if i % 100 == 0:  # at 1 kHz the robot's time in ms runs with the frames published
            newest_ms = (read_json(stats) or {}).get("frames_published", newest_ms)
        forger.sendto(forged_frame(rng, newest_ms), ("127.0.0.1", port))
        time.sleep(max(0.0, started + (i + 1) / RATE - time.monotonic()))  # one between two of the robot's
    forger.close()
    check(h.wait("robot", robot, 30) == 0, "rsg_sim (robot) failed")
    report = read_json(report_path)
    check(report["valid"] == COUNT, f"robot report: {report}")

    sent = report["sent"] + REPLAYED + FORGED
    final = wait_for_stats(stats, lambda s: s["frames_received"] >= sent, f"the gateway to count all {sent} datagrams")
    counters = {key: final.get(key) for key in ("frames_received", "frames_published", "out_of_sequence", "lost",
                                                 "duplicated", "reordered", "robot_restarts")}
    expected = {"frames_received": sent, "frames_published": COUNT, "out_of_sequence": REPLAYED + FORGED,
                "lost": 0, "duplicated": 0, "reordered": 0, "robot_restarts": 0}
    check(counters == expected, f"gateway {counters}\n  != {expected}")

    # The legitimate reader: the robot's frames, each once, in order, nothing else.
    robot_frames = read_json_lines(record)
    wait_for(lambda: read_json_lines(h.output("full"))[-1:] == robot_frames[-1:], "the reader to get the last frame")
    got = read_json_lines(h.output("full"))
    forged = [s for s in got if s["fields"]["q"][0] == FORGED_Q]
    check(not forged, f"the reader got {len(forged)} forged samples, e.g. {forged[:1]}")
    times = [s["fields"]["time"] for s in got]
    backwards = sum(1 for a, b in zip(times, times[1:]) if b <= a)
    check(backwards == 0, f"the reader saw time go backwards {backwards} times")
    check(got == robot_frames, f"the reader got {len(got)} samples, not the robot's {len(robot_frames)} frames")

    # The rate topic: one sample per 1/50 s window of the robot's time that holds a frame, from the
    # robot's frames only (test_rate_topic.py says why the least gap allows the robot's longest step).
    period = 1000 // RATE_HZ
    robot_times = [frame["fields"]["time"] for frame in robot_frames]
    steps = [b - a for a, b in zip(robot_times, robot_times[1:])]
    expected = paced_count(robot_times, period)
    slack = 2 + sum(step >= period for step in steps)
    wait_for(lambda: len(read_json_lines(h.output("slow"))) >= expected - slack, "the rate topic's samples")
    time.sleep(0.5)  # anything more would have arrived by now
    slow_samples = read_json_lines(h.output("slow"))
    check(all(s in robot_frames for s in slow_samples), "the rate topic carried a frame the robot did not send")
    check(len(slow_samples) <= expected + slack,
          f"the {RATE_HZ} Hz topic carried {len(slow_samples)} samples, expected {expected} (± {slack})")
    slow_times = [s["fields"]["time"] for s in slow_samples]
    gaps = [b - a for a, b in zip(slow_times, slow_times[1:])]
    check(all(gap >= period - max(steps) for gap in gaps),
          f"rate topic samples closer than 1/{RATE_HZ} s less the robot's longest step ({max(steps)} ms): {gaps}")

    for label, process in (("full", full), ("slow", slow)):
        process.terminate()
        h.wait(label, process)
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("replay_and_forgery", body))
