"""Reader-kind benchmark: what N readers of each kind cost rsg_gateway at 1 kHz.

    readers.py --bin BUILD/bin [--gateway PATH] [--label NAME] [--counts 0,1,4,16]
               [--kinds plain,view,groups,ros2_filter] [--seconds 8] --out DIR

Per point (kind, N): a fresh rsg_gateway --ros2 on a domain of its own, N readers of the kind, a
1 kHz stream whose every frame carries group 2 (so a view on group 2 takes what a plain reader
takes), and a window of --seconds once both sides matched and the stream runs. For rsg's readers
the reader process is also the robot, sending stamped full frames, and measures the one-way
latency robot -> gateway -> reader (p50/p99 over all its readers); for the ROS 2 kinds and for no
reader, rsg_sim streams. Measured in that window from /proc: the gateway's CPU (percent of one
core) and the readers' process CPU; from the
gateway's stats file: frames published, its largest ingress delay (arrival at the socket to
publication, per second) and the link-down reports it logged in the window. --gateway may be a
wrapper script (the Fast DDS 3 chroot's): CPU is counted over its process tree. Kinds:
  plain        rsg_bench_reader_host --kind plain: N plain DataReaders in one process
  view         ... --kind view: N ViewReaders on view_joints (the client library, as rsg_echo --view)
  groups       ... --kind groups: N ad-hoc group views (rsg_echo --groups 2)
  ros2_filter  one rclpy node with N subscriptions content-filtered with the DDS-SQL expression
               docs/ros2.md recommends (rclpy_peer.py hold: it does not spin; its own cost is not
               what is measured)
  ros2_plain   the same without the filter (the control for ros2_filter)
  ros2_filter_best_effort  ros2_filter with best-effort subscriptions (sensor_data QoS): no repairs,
               so what is left is what the filters cost the gateway (nothing: it evaluates none)
Writes DIR/readers_<label>.json and prints a table; ratios are within this one run. Timings only:
no pass/fail.
"""
import argparse
import json
import os
import signal
import subprocess
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
from harness import acquire_domain, free_udp_port, read_json, realtime_prefix, wait_for  # noqa: E402
from test_domain import release_domain  # noqa: E402  (tests/support, on the path through harness)

TICKS = os.sysconf("SC_CLK_TCK")
ROS_FILTER = "group_present[2] = TRUE"


def cpu_ticks(pid):
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return int(fields[11]) + int(fields[12])  # utime, stime


def tree_ticks(pid):
    """CPU ticks of `pid` and its children (the rclpy node runs under env/bash)."""
    total = 0
    try:
        total = cpu_ticks(pid)
        for child in Path(f"/proc/{pid}/task/{pid}/children").read_text().split():
            total += tree_ticks(int(child))
    except (FileNotFoundError, ProcessLookupError):
        pass
    return total


def terminate(*processes, timeout_s=10):
    """SIGTERM to each process still running (None: none started), SIGKILL after `timeout_s`."""
    for process in processes:
        if process and process.poll() is None:
            process.send_signal(signal.SIGTERM)
            try:
                process.wait(timeout=timeout_s)
            except subprocess.TimeoutExpired:
                process.kill()


def run_point(args, kind, count, domain, scratch):
    port = free_udp_port()
    stats = scratch / f"{kind}_{count}.stats.json"
    gateway_log = scratch / f"{kind}_{count}.gateway.log"
    log = open(gateway_log, "w")
    gateway = subprocess.Popen([args.gateway, "--listen", f"127.0.0.1:{port}", "--domain", str(domain), "--ros2",
                                "--expected-rate", "1000", "--stats-file", str(stats)], stdout=log, stderr=log)
    readers = None
    sim = None
    host_result = None
    robot_silence_us = None
    # rsg's own readers: rsg_bench_reader_host is also the robot (stamped frames, so it measures the
    # latency). Otherwise rsg_sim is, on time (SCHED_FIFO where allowed).
    host = count and not kind.startswith("ros2")
    readers_err = scratch / f"{kind}_{count}.readers.err"
    try:
        wait_for(lambda: read_json(stats), "the gateway to start")
        if host:
            readers = subprocess.Popen([str(Path(args.test_bin) / "rsg_bench_reader_host"),
                                        "--domain", str(domain), "--ros2", "--kind", kind, "--count", str(count),
                                        "--send-to", f"127.0.0.1:{port}", "--settle", "3", "--seconds", str(args.seconds),
                                        "--qos", args.reader_qos],
                                       stdout=subprocess.PIPE, stderr=open(readers_err, "w"), text=True)
        elif count:
            from rclpy_common import RosEnv
            env = RosEnv(domain)
            extra = ["--filter", ROS_FILTER] if kind.startswith("ros2_filter") else []
            extra += ["--best-effort"] if kind.endswith("_best_effort") else []
            readers = subprocess.Popen(env.argv("hold", "--count", count, "--seconds", 600, *extra),
                                       stdout=subprocess.DEVNULL, stderr=open(readers_err, "w"))
        if count:
            wait_for(lambda: (read_json(stats) or {}).get("state_readers", 0) >= count, f"{count} {kind} readers to match",
                     timeout_s=60)
        if host:
            wait_for(lambda: "window start" in readers_err.read_text(), "the reader host's window", timeout_s=60)
        else:
            sim_report = scratch / f"{kind}_{count}.sim.json"
            sim = subprocess.Popen([*realtime_prefix(), str(Path(args.bin) / "rsg_sim"), "--to", f"127.0.0.1:{port}",
                                    "--rate", "1000", "--duration", str(args.seconds + 5), "--report", str(sim_report),
                                    "--every", "1:g2"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(3)  # the stream settles; late discovery traffic ends
        before = read_json(stats)
        downs0 = gateway_log.read_text(errors="replace").count("] link down")
        g0, r0, t0 = tree_ticks(gateway.pid), tree_ticks(readers.pid) if readers else 0, time.monotonic()
        delays = []
        end = t0 + args.seconds
        while time.monotonic() < end:
            time.sleep(min(1.0, max(0.0, end - time.monotonic())))
            current = read_json(stats)
            if current:
                delays.append(current.get("ingress_delay_us", 0))
        g1, r1, t1 = tree_ticks(gateway.pid), tree_ticks(readers.pid) if readers else 0, time.monotonic()
        downs = gateway_log.read_text(errors="replace").count("] link down") - downs0
        after = read_json(stats)
        alive = gateway.poll() is None
        if host:
            out, _ = readers.communicate(timeout=60)
            host_result = json.loads(out.strip().splitlines()[-1])
            robot_silence_us = host_result["sender_longest_gap_us"]
        else:
            sim.wait(timeout=30)
            robot_silence_us = (read_json(sim_report) or {}).get("longest_gap_us")
    finally:
        terminate(sim, readers)
        if gateway.poll() is None:
            gateway.send_signal(signal.SIGTERM)
            gateway.wait(timeout=30)
        log.close()
    seconds = t1 - t0
    return {
        "kind": kind, "readers": count, "seconds": round(seconds, 2), "gateway_alive": alive,
        "gateway_cpu_pct": round(100.0 * (g1 - g0) / TICKS / seconds, 1),
        "readers_cpu_pct": round(100.0 * (r1 - r0) / TICKS / seconds, 1),
        "published_per_s": round((after["frames_published"] - before["frames_published"]) / seconds, 1),
        "latency_p50_us": host_result["latency_p50_us"] if host_result else None,
        "latency_p99_us": host_result["latency_p99_us"] if host_result else None,
        "wrong_samples": host_result["wrong"] if host_result else None,
        "ingress_delay_max_us": max(delays) if delays else None,
        "link_down_reports": downs,
        "robot_longest_silence_us": robot_silence_us,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--bin", required=True)
    parser.add_argument("--test-bin", help="directory of the bench's helpers (default: BIN/../tests/bin, the build "
                                           "tree's: CONTRIBUTING.md, \"Build tree\")")
    parser.add_argument("--gateway", help="rsg_gateway to measure (default: BIN/rsg_gateway)")
    parser.add_argument("--label", default="fastdds2.9")
    parser.add_argument("--counts", default="0,1,4,16")
    parser.add_argument("--kinds", default="plain,view,groups,ros2_filter,ros2_plain")
    parser.add_argument("--seconds", type=float, default=8)
    parser.add_argument("--out", required=True)
    parser.add_argument("--reader-qos", default="reader_realtime",
                        help="rsg readers' profile: reader_realtime (data-sharing on this host) or reader_realtime_udp "
                             "(a gateway of another Fast DDS version: 2.9/3.x data-sharing aborts the writer)")
    args = parser.parse_args()
    args.gateway = args.gateway or str(Path(args.bin) / "rsg_gateway")
    args.test_bin = args.test_bin or str(Path(args.bin).parent / "tests" / "bin")
    counts = [int(c) for c in args.counts.split(",")]
    kinds = args.kinds.split(",")
    points = []
    with tempfile.TemporaryDirectory(prefix="rsg_bench_readers_") as tmp:
        scratch = Path(tmp)
        last_domain = None
        for count in counts:
            for kind in (kinds if count else kinds[:1]):
                # A domain per point, so that no participant of the last point is still discovered
                # (the next one taken before the last is given back: the pool would hand it out again).
                domain = acquire_domain()
                if last_domain is not None:
                    release_domain(last_domain)
                last_domain = domain
                point = run_point(args, kind, count, domain, scratch)
                points.append(point)
                print(json.dumps(point), flush=True)
    cpu_model = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name")), "?")
    result = {"label": args.label, "cpu": cpu_model, "cores": os.cpu_count(), "gateway": args.gateway,
              "reader_qos": args.reader_qos, "points": points}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / f"readers_{args.label}.json").write_text(json.dumps(result, indent=2) + "\n")
    print(table(result))


def table(result):
    by = {(p["kind"], p["readers"]): p for p in result["points"]}
    lines = [f"### {result['label']} on {result['cpu']} ({result['cores']} cores), rsg readers: {result['reader_qos']}", "",
             "| readers | kind | gateway CPU % | × plain | readers' CPU % | published/s | p50 µs | p99 µs | max ingress delay µs | link-down reports | robot's longest silence µs |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for p in result["points"]:
        plain = by.get(("plain", p["readers"]))
        ratio = f"{p['gateway_cpu_pct'] / plain['gateway_cpu_pct']:.2f}" if plain and plain["gateway_cpu_pct"] else "—"
        lines.append(f"| {p['readers']} | {p['kind']} | {p['gateway_cpu_pct']} | {ratio} | {p['readers_cpu_pct']} | "
                     f"{p['published_per_s']} | {p['latency_p50_us'] or '—'} | {p['latency_p99_us'] or '—'} | "
                     f"{p['ingress_delay_max_us']} | {p['link_down_reports']} | "
                     f"{p['robot_longest_silence_us']} |")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
