"""Filtered readers of every kind rsg documents join and leave while the gateway streams at 1 kHz:
the gateway never dies, never reports the link down while the robot streams, and the filtered
readers that stay get exactly the samples carrying their groups, in order.

rsg_gateway --ros2 gets a mixed-selection stream from rsg_sim at 1 kHz. For CHURN_S seconds, in
parallel lanes:
  - the client library (rsg_views_churn): ViewReaders on profile views and ad-hoc group views
    created, read until they got a sample, deleted; a new participant every few readers;
  - rsg_echo --view / --groups processes, stopped with SIGTERM and SIGKILL in turn;
  - rclpy subscriptions with the content filter docs/ros2.md recommends (DDS-SQL), in processes
    stopped with SIGTERM and SIGKILL in turn, and in one process that inits and shuts down
    contexts (each a participant) in a loop.
(Cyclone 0.10's C API has no content-filtered topic that reaches the writer: its readers filter in
their own process, which tests/interop already covers.) The test then checks the gateway is
running, logged no "link down" and published every valid frame; then, with the churn over,
three filtered readers (a view, an ad-hoc group view, an rclpy content filter) get a 2000-frame
run and must print exactly the frames carrying their groups. The cycle counts and the gateway's
longest ingress delay are printed, not judged (timings belong in make bench).
"""
import json
import os
import signal
import sys
import threading
import time
from pathlib import Path

from harness import (check, free_udp_port, main, read_json, read_json_lines, realtime_prefix, wait_for,  # noqa: E402
                     wait_for_stats)
from rclpy_common import RosEnv, check_in_order, read_messages, start_peer, wait_peer_matched  # noqa: E402

CHURN_S = 40
FINAL_COUNT = 2000
STREAM = ["--every", "1:g2", "--every", "3:g3", "--every", "10:g0,g5", "--every", "50:all"]
ROS_FILTER = "group_present[2] = TRUE AND group_present[3] = TRUE"
# RSG_CHURN_CONTROL=1: the same churn with plain readers only, the control for the stall figures
# (docs/benchmarks/views_churn.md); the final checks are the same.
CONTROL = bool(os.environ.get("RSG_CHURN_CONTROL"))
# RSG_CHURN_GATEWAY_ARGS="--rt-priority 30": more flags for the gateway (real-time mode), for the
# stall figures of docs/benchmarks/readers/README.md.
GATEWAY_ARGS = os.environ.get("RSG_CHURN_GATEWAY_ARGS", "").split()
# RSG_CHURN_REPORT=FILE: the printed figures as JSON too (tests/bench/readers/churn.py reads them).
REPORT = os.environ.get("RSG_CHURN_REPORT")
ECHO_VIEWS = [["--view", "view_kinematics"], ["--groups", "2,3"], ["--view", "view_joints"], ["--view", "view_forces"]]


def lane(stop_at, cycles, step):
    """Runs `step(index)` until `stop_at`; counts completed cycles in `cycles` (a one-item list)."""
    index = 0
    while time.monotonic() < stop_at:
        step(index)
        index += 1
        cycles[0] = index


def stop_child(process, index):
    """SIGTERM on even cycles, SIGKILL on odd ones: a reader that says goodbye, and one that vanishes."""
    process.send_signal(signal.SIGTERM if index % 2 == 0 else signal.SIGKILL)
    try:
        process.wait(timeout=20)
    except Exception:  # noqa: a reader that ignores SIGTERM is not what this test is about
        process.kill()
        process.wait()


def body(h):
    env = RosEnv(h.domain)
    port = free_udp_port()
    gateway, stats = h.gateway("gw", "--listen", f"127.0.0.1:{port}", "--expected-rate", "1000", "--ros2", *GATEWAY_ARGS)
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    echo = h.binary("rsg_echo")
    domain = ["--domain", str(h.domain)]

    # The churn stream, as a robot streams: on time. rsg_sim runs under SCHED_FIFO when this
    # process may ask for it (root), so that a loaded 2-core host does not make the "robot" itself
    # fall silent; its report's longest_gap_us says how long it really was silent, either way.
    sim_report = h.dir / "sim_churn.report.json"
    sim = h.start("sim_churn", [*realtime_prefix(), h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000",
                                "--duration", str(CHURN_S + 15), "--report", str(sim_report), *STREAM])
    wait_for_stats(stats, lambda s: s["frames_published"] >= 500 and s["link_up"], "the stream to start")
    stop_at = time.monotonic() + CHURN_S

    # reader_realtime_udp: a volatile data-sharing reader that joins a writer while it writes can
    # abort *itself* on Fast DDS 2.9.1 (ReaderPool::init_shared_segment's assertion, fixed upstream
    # in PR 4321, 2.13.3; docs/operating.md), once in about a thousand joins here; that is the
    # reader's failure, not what this test is about.
    qos = "reader_realtime_udp"
    library = h.start("library", [h.binary("rsg_views_churn"), *domain, "--ros2", "--seconds", str(CHURN_S),
                                  "--hold", "0.5", "--participant-every", "5", "--qos", qos,
                                  *(["--plain"] if CONTROL else [])])
    counts = {"echo": [0], "rclpy_process": [0]}
    rclpy_loop = start_peer(h, env, "rclpy_loop", "churn", "--count", 12, "--topic", "/robot_state", "--hold", 1,
                            *([] if CONTROL else ["--filter", ROS_FILTER]))

    def echo_step(index):
        view = [] if CONTROL else ECHO_VIEWS[index % len(ECHO_VIEWS)]
        process = h.start(f"echo{index}", [echo, *domain, "--ros2", *view, "--json", "--timeout", "30"])
        time.sleep(0.4 + 0.2 * (index % 3))
        stop_child(process, index)

    def rclpy_step(index):
        label = f"rclpy{index}"
        process = start_peer(h, env, label, "sub", "/robot_state", "rsg_msgs/msg/RobotState",
                             *([] if CONTROL else ["--filter", ROS_FILTER]), "--timeout", 30)
        err = h.dir / f"{label}.err"
        deadline = time.monotonic() + 8
        while time.monotonic() < deadline and not (err.exists() and "matched 1" in err.read_text(errors="replace")):
            time.sleep(0.05)
        time.sleep(0.3)
        stop_child(process, index)

    lanes = [threading.Thread(target=lane, args=(stop_at, counts["echo"], echo_step)),
             threading.Thread(target=lane, args=(stop_at, counts["rclpy_process"], rclpy_step))]
    link_seen_down = []

    def watch():
        while time.monotonic() < stop_at:
            current = read_json(stats)
            if current and not current["link_up"]:
                link_seen_down.append(current)
            time.sleep(0.1)
    watcher = threading.Thread(target=watch)
    for thread in [*lanes, watcher]:
        thread.start()
    for thread in [*lanes, watcher]:
        thread.join()
    library_status = h.wait("library", library, 60)
    check(library_status != 1, "the client library's view readers got a sample without their groups")
    check(library_status == 0, f"rsg_views_churn failed (exit {library_status}): see library.err")
    check(h.wait("rclpy_loop", rclpy_loop, 120) == 0, "an rclpy content-filtered subscription got a wrong message")

    check(gateway.poll() is None, f"the gateway died during the churn (exit {gateway.returncode})")
    check(sim.poll() is None, "rsg_sim stopped during the churn")
    during = read_json(stats)
    link_downs = (h.dir / "gw.err").read_text(errors="replace").count("link down")
    check(h.wait("sim_churn", sim, CHURN_S + 60) == 0, "rsg_sim failed")
    silent_us = read_json(sim_report)["longest_gap_us"]
    # The gateway judges silence by arrival time stamps (10 ms at 1 kHz): it may report the link
    # down only if the robot really was silent that long.
    check((link_downs == 0 and not link_seen_down) or silent_us >= 10_000,
          f"the gateway reported the link down {link_downs} times while the robot streamed "
          f"(its longest silence {silent_us} us)")
    check(during["publish_failed"] == 0, f"{during['publish_failed']} valid frames the writer refused")
    library_out = h.output("library").read_text().strip()
    loop_err = (h.dir / "rclpy_loop.err").read_text(errors="replace").strip().splitlines()
    print(f"[views_churn] {CHURN_S} s at 1 kHz: client library {library_out}; rsg_echo processes {counts['echo'][0]}; "
          f"rclpy processes {counts['rclpy_process'][0]}; rclpy contexts: {loop_err[-1] if loop_err else '?'}; "
          f"gateway ingress delay max {during['ingress_delay_max_us']} us; robot's longest silence {silent_us} us; "
          f"link-down reports {link_downs}", flush=True)
    if REPORT:
        Path(REPORT).write_text(json.dumps({
            "control": CONTROL, "seconds": CHURN_S, "client_library": library_out,
            "rsg_echo_processes": counts["echo"][0], "rclpy_processes": counts["rclpy_process"][0],
            "ingress_delay_max_us": during["ingress_delay_max_us"], "robot_longest_silence_us": silent_us,
            "link_down_reports": link_downs}))

    # The readers that stay: exactly their frames, in order. First every churned reader must be
    # gone from the writer's count (the SIGKILLed ones by lease expiry), or the count below could be
    # met by stale readers before the writer matched the new ones, and they would miss the start.
    wait_for_stats(stats, lambda s: s["state_readers"] == 0, "the churned readers to leave the writer", timeout_s=90)
    finals = {"final_view": (["--view", "view_forces"], 0b001100), "final_groups": (["--groups", "3,5"], 0b101000)}
    for label, (args, _) in finals.items():
        h.start(label, [echo, *domain, "--ros2", *args, "--json", "--timeout", "5"])
    start_peer(h, env, "final_rclpy", "sub", "/robot_state", "rsg_msgs/msg/RobotState", "--qos", "keep_all",
               "--filter", ROS_FILTER, "--count", 0, "--idle", "4", "--timeout", 120)
    wait_for_stats(stats, lambda s: s["state_readers"] >= 3, "the final readers to match the gateway")
    for label in finals:
        wait_for(lambda label=label: "rsg_echo: matched 1 writer of " in (h.dir / f"{label}.err").read_text(errors="replace"),
                 f"{label} to match")
    wait_peer_matched(h, "final_rclpy")
    record = h.dir / "final.jsonl"
    check(h.run("sim_final", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count",
                              str(FINAL_COUNT), *STREAM, "--record", str(record)], timeout_s=60) == 0, "rsg_sim failed")
    sent_lines = record.read_text().splitlines()
    check(len(sent_lines) == FINAL_COUNT, f"rsg_sim recorded {len(sent_lines)} frames")
    for label, (_, groups) in finals.items():
        process = dict(h.children)[label]
        h.wait(label, process, 60)
        printed = h.output(label).read_text().splitlines()
        expected = [line for line in sent_lines if json.loads(line)["group_select"] & groups == groups]
        check(printed == expected, f"{label}: printed {len(printed)} samples, not exactly the {len(expected)} "
                                   f"frames carrying groups {groups:#08b} in order")
    check(h.wait("final_rclpy", dict(h.children)["final_rclpy"], 60) == 0, "the final rclpy subscription failed")
    sent = [json.loads(line) for line in sent_lines]
    got = read_messages(h, "final_rclpy")
    wanted = [index for index, frame in enumerate(sent) if frame["group_select"] & 0b1100 == 0b1100]
    check(got and check_in_order("rclpy content filter", sent, got, list(got[0])) == wanted,
          f"the content-filtered rclpy subscription got {len(got)} messages, not exactly the {len(wanted)} frames "
          f"carrying groups 2 and 3")
    check(gateway.poll() is None, "the gateway died")
    check(h.stop("gw", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("views_churn", body))
