"""make bench's ros2_rate suite: the sustained rate a plain rclpy subscriber receives from
rsg_gateway --ros2 at 1 kHz, on ROS 2 Jazzy (Kilted's runs, before
its retirement: docs/benchmarks/ros2_rate/), next to the floor, a plain rclpy
publisher at 1 kHz to the same subscriber.

    ros2_rate.py --bin BUILD/bin [--distros jazzy] [--seconds 60] [--settle 3] --out DIR
    ros2_rate.py --table DIR/ros2_rate.json      (prints the table of a saved run)

Per distribution (make deps' ROS 2 environment, ros2/env.sh with RSG_ROS_DISTRO), on a DDS domain
of its own, two runs one after the other:
  rclpy_publisher  rate_peer.py pub: an rclpy timer of 1 ms publishing rsg_msgs/msg/RobotState
                   (default QoS) from a node of the same distribution: what rclpy itself sustains
  rsg_gateway      rsg_sim at 1 kHz (SCHED_FIFO where allowed, as a robot is on time) ->
                   rsg_gateway --ros2 (default reliable QoS on /robot_state) -> the subscriber
The subscriber is rate_peer.py sub: rclpy's default QoS (reliable, keep last 10), spun by
rclpy.spin_once, measuring --seconds once its first message came and --settle seconds passed:
messages per second, lost (frames missing from the span of their `time` member: one per ms),
duplicates, inter-arrival p50/p99/max, its own CPU. Neither the subscriber nor the rclpy publisher
gets a real-time priority: they are what a ROS 2 user runs. Writes DIR/ros2_rate.json and
DIR/ros2_rate.md (the table). Timings only: no pass/fail.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
from harness import acquire_domain, free_udp_port, read_json, wait_for  # noqa: E402
from rclpy_common import RosEnv  # noqa: E402
from test_domain import release_domain  # noqa: E402  (tests/support, on the path through harness)

sys.path.insert(0, str(HERE.parent / "readers"))
from readers import realtime_prefix, terminate as stop  # noqa: E402

PEER = HERE / "rate_peer.py"
FASTDDS = {"jazzy": "2.14", "kilted": "3.2"}  # kilted: the committed runs of docs/benchmarks/ros2_rate/


def last_json(path):
    lines = [line for line in Path(path).read_text(errors="replace").splitlines() if line.startswith("{")]
    return json.loads(lines[-1]) if lines else {"error": f"nothing printed (see {path})"}


def run_subscriber(env, args, scratch, label):
    out = scratch / f"{label}.sub.out"
    process = subprocess.Popen(env.script_argv(PEER, "sub", "--settle", args.settle, "--seconds", args.seconds),
                               stdout=open(out, "w"), stderr=open(scratch / f"{label}.sub.err", "w"))
    return process, out


def floor(env, args, scratch):
    label = f"{env.distro}_rclpy_publisher"
    sub, sub_out = run_subscriber(env, args, scratch, label)
    pub_out = scratch / f"{label}.pub.out"
    # The publisher's clock starts when the subscription matched, before the subscriber's first
    # message: it outlasts the subscriber's window by the time to that message and ends by itself.
    pub = subprocess.Popen(env.script_argv(PEER, "pub", "--rate", 1000, "--seconds", args.settle + args.seconds + 5),
                           stdout=open(pub_out, "w"), stderr=open(scratch / f"{label}.pub.err", "w"))
    try:
        sub.wait(timeout=args.settle + args.seconds + 120)
        pub.wait(timeout=30)
    finally:
        stop(sub, pub)
    source = last_json(pub_out) if pub_out.read_text().strip() else {}
    return {"source": "rclpy_publisher", "subscriber": last_json(sub_out),
            "source_rate_hz": source.get("rate_hz")}


def gateway(env, args, scratch):
    label = f"{env.distro}_rsg_gateway"
    port = free_udp_port()
    stats = scratch / f"{label}.stats.json"
    log = open(scratch / f"{label}.gateway.log", "w")
    gw = subprocess.Popen([str(Path(args.bin) / "rsg_gateway"), "--listen", f"127.0.0.1:{port}", "--domain",
                           str(env.domain), "--ros2", "--expected-rate", "1000", "--stats-file", str(stats)],
                          stdout=log, stderr=log)
    sub = sim = None
    try:
        wait_for(lambda: read_json(stats), "the gateway to start")
        sub, sub_out = run_subscriber(env, args, scratch, label)
        wait_for(lambda: (read_json(stats) or {}).get("state_readers", 0) >= 1, "the rclpy subscription to match",
                 timeout_s=60)
        report = scratch / f"{label}.sim.json"
        sim = subprocess.Popen([*realtime_prefix(), str(Path(args.bin) / "rsg_sim"), "--to", f"127.0.0.1:{port}",
                                "--rate", "1000", "--duration", str(args.settle + args.seconds + 15),
                                "--report", str(report)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        sub.wait(timeout=args.settle + args.seconds + 120)
        final = read_json(stats) or {}
    finally:
        stop(sub, sim, gw)
        log.close()
    return {"source": "rsg_gateway", "subscriber": last_json(sub_out), "source_rate_hz": 1000,
            "gateway_frames_published": final.get("frames_published"),
            "gateway_publish_failed": final.get("publish_failed"), "gateway_lost_upstream": final.get("lost")}


def table(result):
    lines = [f"### rclpy subscriber at 1 kHz, {result['seconds']:.0f} s per run, on {result['cpu']} "
             f"({result['cores']} cores)", "",
             "| ROS 2 node (its Fast DDS) | source | received/s | received | lost | duplicates "
             "| inter-arrival p50 / p99 / max ms | subscriber CPU % | source's rate | load average before |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for run in result["runs"]:
        sub = run["subscriber"]
        node = f"{run['distro'].capitalize()} ({FASTDDS.get(run['distro'], '?')})"
        if "error" in sub:
            lines.append(f"| {node} | {run['source']} | failed: {sub['error']} | | | | | | | |")
            continue
        gaps = sub["interarrival_ms"]
        source = "rsg_sim 1000 Hz" if run["source"] == "rsg_gateway" else f"{run['source_rate_hz']} Hz"
        lines.append(f"| {node} | {'`rsg_gateway --ros2` (Fast DDS 2.9.1)' if run['source'] == 'rsg_gateway' else 'rclpy publisher, same distribution'} "
                     f"| {sub['rate_hz']} | {sub['received']} | {sub['lost']} | {sub['duplicates']} "
                     f"| {gaps['p50']} / {gaps['p99']} / {gaps['max']} | {sub['cpu_pct']} | {source} "
                     f"| {run['load_average_before'][0]} |")
    return "\n".join(lines)


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--table":  # the table of a saved ros2_rate.json
        print(table(json.loads(Path(sys.argv[2]).read_text())))
        return
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--bin", required=True)
    parser.add_argument("--distros", default="jazzy")
    parser.add_argument("--seconds", type=float, default=60)
    parser.add_argument("--settle", type=float, default=3)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    runs = []
    with tempfile.TemporaryDirectory(prefix="rsg_bench_ros2_rate_") as tmp:
        scratch = Path(tmp)
        for distro in args.distros.split(","):
            for kind in (floor, gateway):
                # A domain per run: nothing of the last run is still discovered.
                domain = acquire_domain()
                try:
                    env = RosEnv(domain, distro)
                    load = open("/proc/loadavg").read().split()[:3]
                    started = time.monotonic()
                    run = {"distro": distro, **kind(env, args, scratch), "load_average_before": load,
                           "wall_s": round(time.monotonic() - started, 1)}
                finally:
                    release_domain(domain)
                runs.append(run)
                print(json.dumps(run), flush=True)
    cpu_model = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name")), "?")
    result = {"cpu": cpu_model, "cores": os.cpu_count(), "seconds": args.seconds, "settle_s": args.settle,
              "runs": runs}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "ros2_rate.json").write_text(json.dumps(result, indent=2) + "\n")
    (out / "ros2_rate.md").write_text(table(result) + "\n")
    print(table(result))


if __name__ == "__main__":
    main()
