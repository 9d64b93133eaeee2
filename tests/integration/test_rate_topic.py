"""--rate-topic NAME:HZ: a second RobotState topic carrying the frames that fall due at HZ, paced by
the robot's `time`, while the full-rate topic still gets every frame; NAME:every:N: every Nth frame. Counts, not timings: rsg_sim's
`time` advances 2 ms per frame at 500 Hz, so 500 frames span 1 s of robot time whatever the load."""

import sys
import time

from harness import check, free_udp_port, main, paced_count, read_json_lines, wait_for, wait_for_stats, wait_reader_matched

COUNT = 500
WARM_UP_MAX = 10000  # 20 s at 500 Hz at most; stopped once every rate reader got a sample
WARM_UP_PAST_MS = 200  # twice the gateway's default --restart-threshold-ms (100)
RATE = "500"


def body(h):
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", RATE,
                               "--rate-topic", "robot_state_50hz:50", "--rate-topic", "robot_state_10hz:10",
                               "--rate-topic", "robot_state_tenth:every:10")
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    # The rate readers end on their idle timeout; it must outlast their discovery on a loaded host.
    echo = lambda label, topic, count, idle: h.start(label, [  # noqa: E731
        h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", topic, "--json", "--count", str(count),
        "--timeout", str(idle)])
    full = echo("full", "robot_state", 10**9, 60)  # read to the end, then killed
    slow = echo("slow", "robot_state_50hz", COUNT, 8)
    slower = echo("slower", "robot_state_10hz", COUNT, 8)
    tenth = echo("tenth", "robot_state_tenth", COUNT, 8)
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, "the full-rate reader to match")
    wait_reader_matched(h, "full", "rsg_echo")
    # The rate readers are volatile: a warm-up stream (q and time only) runs until each got a sample,
    # so that the measured stream (every field) starts with every reader matched.
    warm_up = h.start("warm_up", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count",
                                  str(WARM_UP_MAX), "--fields", "q,time"])
    for label in ("slow", "slower", "tenth"):
        wait_for(lambda: h.output(label).stat().st_size > 0, f"{label} to get a warm-up sample")
    # And until the warm-up's robot time is past the gateway's restart threshold (100 ms): the
    # measured run starts again at time 0, which the gateway takes for a restart only when time goes
    # back by more than that; nearer, its first frame reads as a duplicate of the warm-up's and is
    # not published. Fast DDS 3.6 matched the rate readers after 2 warm-up frames (time 2 ms).
    wait_for(lambda: any(sample["fields"]["time"] > WARM_UP_PAST_MS for sample in read_json_lines(h.output("full"))),
             f"the warm-up to pass {WARM_UP_PAST_MS} ms of robot time")
    h.stop("warm_up", warm_up)
    # The measured run's times start again from 0: the gateway takes it for a new sequence once the
    # warm-up has been silent for the link's silence limit (docs/operating.md), 20 ms at 500 Hz.
    time.sleep(0.2)
    record = h.dir / "sim.record.jsonl"
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count", str(COUNT),
                           "--record", str(record)])
    check(status == 0, f"rsg_sim exited {status}")
    sent = read_json_lines(record)
    last = lambda: (read_json_lines(h.output("full")) or [None])[-1]  # noqa: E731
    wait_for(lambda: last() == sent[-1], "the full-rate topic to get the last frame")
    h.wait("slow", slow, 45)
    h.wait("slower", slower, 45)
    h.wait("tenth", tenth, 45)
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")

    check(read_json_lines(h.output("full"))[-COUNT:] == sent, "the full-rate topic differs from what the sim sent")
    # Paced by the robot's time: one sample per 1/hz window that holds a frame. A sample is the first
    # frame at or after its due time, so it comes late by less than the robot's longest step between
    # two frames (2 ms at 500 Hz, more wherever the robot's time jumps), and
    # the next is due a period after the due time: the least gap is the period less that step.
    sent_times = [frame["fields"]["time"] for frame in sent]
    steps = [b - a for a, b in zip(sent_times, sent_times[1:])]
    for label, hz in (("slow", 50), ("slower", 10)):
        period = 1000 // hz
        got = [sample for sample in read_json_lines(h.output(label)) if sample["group_select"] == 63]
        times = [sample["fields"]["time"] for sample in got]
        expected = paced_count(sent_times, period)
        slack = 2 + sum(step >= period for step in steps)  # the pacing starts again after such a gap
        check(abs(len(got) - expected) <= slack, f"{label}: {len(got)} samples, expected {expected} (± {slack})")
        check(all(sample in sent for sample in got), f"{label}: a sample that was not sent")
        gaps = [b - a for a, b in zip(times, times[1:])]
        check(all(gap >= period - max(steps) for gap in gaps),
              f"{label}: samples closer than 1/{hz} s less the robot's longest step ({max(steps)} ms): {gaps}")
    # every:10 counts frames, not time: exactly every 10th frame of the measured stream, in order.
    got = [sample for sample in read_json_lines(h.output("tenth")) if sample["group_select"] == 63]
    check(len(got) == COUNT // 10, f"tenth: {len(got)} samples of {COUNT} frames, expected {COUNT // 10}")
    first = sent.index(got[0])
    check(first < 10 and got == sent[first::10], "tenth: not every 10th frame sent")


if __name__ == "__main__":
    sys.exit(main("rate_topic", body))
