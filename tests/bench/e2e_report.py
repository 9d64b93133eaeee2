#!/usr/bin/env python3
"""Merges the rsg_bench_e2e results of one run into results.json, results.md and latency_cdf.png.

    e2e_report.py RUN_DIR OUT_DIR
    e2e_report.py --render OUT_DIR     (results.md again from OUT_DIR/results.json)

RUN_DIR holds one <scenario>.json per scenario (and <scenario>.cdf for latency scenarios) and the
suite's settings.json, as run_bench.sh's `e2e` suite writes them. The goals are judged here, from ratios of the same run,
so that they are recomputed whenever the numbers are. Standard library and gnuplot only.
"""

import datetime
import json
import os
import platform
import shutil
import subprocess
import sys
from pathlib import Path

# Rows of the latency table, in the order a reader compares them: each gateway variant after
# the baselines it is judged against.
LATENCY_ROWS = [
    ("baseline_udp_oneway", "UDP loopback one way (2137-byte datagram)"),
    ("baseline_fastdds", "plain Fast DDS writer -> reader, UDP"),
    ("gateway_udp", "**gateway e2e, UDP**"),
    ("gateway_udp_ros2_standard", "**gateway e2e, UDP, + JointState, TF, wrench at 100 Hz**"),
    ("baseline_fastdds_shm", "plain Fast DDS writer -> reader, SHM"),
    ("gateway_shm", "**gateway e2e, SHM**"),
    ("baseline_fastdds_datasharing", "plain Fast DDS writer -> reader, data-sharing"),
    ("gateway_datasharing", "**gateway e2e, data-sharing**"),
    ("cyclone_ddsperf", "Cyclone DDS ddsperf ping/pong ÷ 2 (UDP)"),
    # The floor: the leanest relay on each DDS API, and the gateway, each read by both vendors.
    ("floor_relay_cyclone_to_cyclone", "leanest relay on Cyclone -> Cyclone reader"),
    ("floor_relay_fastdds_to_cyclone", "leanest relay on Fast DDS -> Cyclone reader"),
    ("floor_gateway_to_cyclone", "**gateway e2e, UDP -> Cyclone reader**"),
    ("floor_relay_cyclone_to_fastdds", "leanest relay on Cyclone -> Fast DDS reader"),
    ("floor_relay_fastdds_to_fastdds", "leanest relay on Fast DDS -> Fast DDS reader"),
    # gateway_udp above is the gateway read by Fast DDS
    ("embedded_callback", "**embedded gateway: datagram -> callback in the same process**"),
]
# The percentiles results.json keeps per scenario (besides counts and scenario-specific keys).
PERCENTILES = ["min_us", "mean_us", "p50_us", "p90_us", "p99_us", "p99.9_us", "max_us"]

P50_SUM_FACTOR = 1.25
P99_SUM_FACTOR = 2.0
# "Clearly below": data-sharing must save at least a fifth of the UDP path's median.
DATASHARING_FRACTION = 0.8
MIN_ZERO_LOSS_RATE_HZ = 20000
MAX_CPU_PERCENT = 5.0
MAX_RSS_GROWTH_KB = 1024
# Issue 14: the gateway against the leanest relay read by the same reader, the Fast DDS reader
# against the Cyclone one, and the embedded callback against a raw UDP hop.
FLOOR_P50_FACTOR = 1.1
FLOOR_P99_FACTOR = 1.25
READER_P50_FACTOR = 1.1
EMBEDDED_P50_FACTOR = 1.5
EMBEDDED_P99_FACTOR = 3.0


def read_json(path):
    with open(path, encoding="utf-8") as file:
        return json.load(file)


def load_runs(run_dir):
    """{scenario: its result} for every scenario that ran."""
    names = [name for name, _ in LATENCY_ROWS] + ["max_rate", "max_rate_datasharing", "soak"]
    return {name: read_json(run_dir / f"{name}.json") for name in names if (run_dir / f"{name}.json").exists()}


def command_output(*command):
    try:
        return subprocess.run(command, capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "?"


def fastdds_version():
    """The installed Fast DDS library package's version: libfastrtps2.x (Debian 12) or libfastdds3.x."""
    for pattern in ("libfastrtps2*", "libfastdds3*"):
        for line in command_output("dpkg-query", "-W", "-f=${Version}\\n", pattern).splitlines():
            if line and line != "?":
                return line
    return "?"


def machine():
    lscpu = {}
    for line in command_output("lscpu").splitlines():
        key, _, value = line.partition(":")
        lscpu[key.strip()] = value.strip()
    return {
        "cpu_model": lscpu.get("Model name", "?"),
        "cpus": os.cpu_count(),
        "hypervisor": lscpu.get("Hypervisor vendor", "none"),
        "kernel": platform.release(),
        "fastdds": fastdds_version(),
        "cyclonedds": command_output("dpkg-query", "-W", "-f=${Version}", "cyclonedds-tools"),
    }


def goal(name, value, limit, passed, how):
    return {"goal": name, "value": value, "limit": limit, "pass": bool(passed), "how": how}


def judge(results):
    """The issue's goals, each as measured value vs limit from this run's own numbers."""
    goals = []
    udp, plain, gateway = (results.get(k) for k in ("baseline_udp_oneway", "baseline_fastdds", "gateway_udp"))
    if udp and plain and gateway:
        p50_sum = udp["p50_us"] + plain["p50_us"]
        goals.append(goal("gateway e2e p50 (UDP) <= 1.25 x (UDP one-way p50 + plain Fast DDS p50)",
                          gateway["p50_us"], P50_SUM_FACTOR * p50_sum,
                          gateway["p50_us"] <= P50_SUM_FACTOR * p50_sum,
                          f"ratio to the sum {gateway['p50_us'] / p50_sum:.2f}"))
        goals.append(goal("gateway e2e p99 (UDP) <= 2 x (UDP one-way p50 + plain Fast DDS p50)",
                          gateway["p99_us"], P99_SUM_FACTOR * p50_sum,
                          gateway["p99_us"] <= P99_SUM_FACTOR * p50_sum,
                          f"ratio to the p50 sum {gateway['p99_us'] / p50_sum:.2f}; to the p99 sum "
                          f"({udp['p99_us'] + plain['p99_us']:.0f} us) "
                          f"{gateway['p99_us'] / (udp['p99_us'] + plain['p99_us']):.2f}"))
    shared = results.get("gateway_datasharing")
    if shared and gateway:
        limit = DATASHARING_FRACTION * gateway["p50_us"]
        goals.append(goal("gateway e2e p50, data-sharing clearly below UDP (<= 0.8 x)", shared["p50_us"],
                          limit, shared["p50_us"] <= limit and shared.get("data_sharing_used"),
                          f"ratio {shared['p50_us'] / gateway['p50_us']:.2f}; data-sharing "
                          f"{'used' if shared.get('data_sharing_used') else 'NOT used'}"))
    goals += judge_floor(results)
    if "max_rate_zero_loss_hz" in results:
        rate = results["max_rate_zero_loss_hz"]
        shared_rate = results.get("max_rate_datasharing_zero_loss_hz")
        goals.append(goal("zero loss at >= 20 kHz over 10 s (gateway, UDP)", rate, MIN_ZERO_LOSS_RATE_HZ,
                          rate >= MIN_ZERO_LOSS_RATE_HZ,
                          "highest step rate without a lost frame"
                          + (f"; data-sharing: {shared_rate:,.0f} Hz" if shared_rate is not None else "")))
    if "cpu_percent_1khz" in results:
        cpu = results["cpu_percent_1khz"]
        goals.append(goal("gateway CPU at 1 kHz <= 5 % of one core", cpu, MAX_CPU_PERCENT,
                          cpu <= MAX_CPU_PERCENT, "utime+stime over the gateway_udp run"))
    if "rss_growth_kb" in results:
        growth = results["rss_growth_kb"]
        goals.append(goal("gateway RSS growth over the soak <= 1 MB", growth, MAX_RSS_GROWTH_KB,
                          growth <= MAX_RSS_GROWTH_KB,
                          f"VmRSS after warm-up vs end of a {results['soak']['duration_s']:.0f} s run"))
    return goals


def judge_floor(results):
    """Issue 14's goals: ratios against the floor of the same run."""
    goals = []
    gateways = {"cyclone": results.get("floor_gateway_to_cyclone"), "fastdds": results.get("gateway_udp")}
    for reader, gateway in gateways.items():
        relays = [(name, results[f"floor_relay_{name}_to_{reader}"]) for name in ("cyclone", "fastdds")
                  if f"floor_relay_{name}_to_{reader}" in results]
        if not gateway or not relays:
            continue
        name, leanest = min(relays, key=lambda relay: relay[1]["p50_us"])
        others = "; ".join(f"vs relay on {n}: p50 {gateway['p50_us'] / r['p50_us']:.2f} x, "
                           f"p99 {gateway['p99_us'] / r['p99_us']:.2f} x" for n, r in relays)
        goals.append(goal(f"gateway p50 <= 1.1 x the leanest relay, both read by {reader}", gateway["p50_us"],
                          FLOOR_P50_FACTOR * leanest["p50_us"],
                          gateway["p50_us"] <= FLOOR_P50_FACTOR * leanest["p50_us"],
                          f"leanest: the relay on {name} ({leanest['p50_us']:.1f} us); {others}"))
        goals.append(goal(f"gateway p99 <= 1.25 x the same relay, both read by {reader}", gateway["p99_us"],
                          FLOOR_P99_FACTOR * leanest["p99_us"],
                          gateway["p99_us"] <= FLOOR_P99_FACTOR * leanest["p99_us"],
                          f"relay on {name}: p99 {leanest['p99_us']:.1f} us"))
    if gateways["cyclone"] and gateways["fastdds"]:
        fast, cyclone = gateways["fastdds"]["p50_us"], gateways["cyclone"]["p50_us"]
        goals.append(goal("gateway read by Fast DDS: p50 <= 1.1 x read by Cyclone", fast, READER_P50_FACTOR * cyclone,
                          fast <= READER_P50_FACTOR * cyclone, f"ratio {fast / cyclone:.2f}"))
    udp, shared = results.get("gateway_udp"), results.get("gateway_datasharing")
    if udp and shared:
        goals.append(goal("gateway data-sharing p50 not slower than UDP", shared["p50_us"], udp["p50_us"],
                          shared["p50_us"] <= udp["p50_us"], f"ratio {shared['p50_us'] / udp['p50_us']:.2f}"))
    embedded, raw = results.get("embedded_callback"), results.get("baseline_udp_oneway")
    if embedded and raw:
        goals.append(goal("embedded callback p50 <= 1.5 x UDP one way p50", embedded["p50_us"],
                          EMBEDDED_P50_FACTOR * raw["p50_us"],
                          embedded["p50_us"] <= EMBEDDED_P50_FACTOR * raw["p50_us"],
                          f"ratio {embedded['p50_us'] / raw['p50_us']:.2f}"))
        goals.append(goal("embedded callback p99 <= 3 x UDP one way p99", embedded["p99_us"],
                          EMBEDDED_P99_FACTOR * raw["p99_us"],
                          embedded["p99_us"] <= EMBEDDED_P99_FACTOR * raw["p99_us"],
                          f"ratio {embedded['p99_us'] / raw['p99_us']:.2f}; its DDS reader at the same time: "
                          f"p50 {embedded['dds_reader']['p50_us']:.1f}, p99 {embedded['dds_reader']['p99_us']:.1f} us"))
    return goals


def merge(runs, settings):
    results = {
        "date": datetime.datetime.now().astimezone().isoformat(timespec="seconds"),
        "machine": machine(),
        "settings": settings,
        # Per run: the 1/5/15-minute load averages at its start and end (also inside each run).
        "load_average": {name: run.get("load_average") for name, run in runs.items()},
    }
    for name, _ in LATENCY_ROWS:
        if name in runs:
            results[name] = runs[name]
    if "max_rate" in runs:
        results["max_rate_zero_loss_hz"] = runs["max_rate"]["max_rate_zero_loss_hz"]
        results["max_rate"] = runs["max_rate"]
    if "max_rate_datasharing" in runs:
        results["max_rate_datasharing_zero_loss_hz"] = runs["max_rate_datasharing"]["max_rate_zero_loss_hz"]
        results["max_rate_datasharing"] = runs["max_rate_datasharing"]
    if "gateway_udp" in runs:
        results["cpu_percent_1khz"] = runs["gateway_udp"]["gateway"]["cpu_percent"]
    if "soak" in runs:
        soak = runs["soak"]
        results["rss_growth_kb"] = soak["gateway"]["rss_growth_kb"]
        results["soak"] = {key: soak[key] for key in ("duration_s", "rate_hz", "sent", "lost", "p50_us", "p99_us")}
        results["soak"]["gateway"] = soak["gateway"]
        results["soak"]["concurrent_with_other_runs"] = settings.get("soak_concurrent", False)
    results["goals"] = judge(results)
    return results


def fmt(value, digits=1):
    if value is None:
        return "–"
    return f"{value:,.{digits}f}" if isinstance(value, float) else f"{value:,}"


def markdown(results):
    m = results["machine"]
    lines = [
        "# rsg end-to-end benchmark: results",
        "",
        f"{results['date']} · {m['cpu_model']}, {m['cpus']} CPUs ({m['hypervisor']} guest) · "
        f"Linux {m['kernel']} · Fast DDS {m['fastdds']} · Cyclone DDS {m['cyclonedds']}",
        "",
        "Generated by `tests/bench/e2e_report.py` from one run of `make bench` (suite `e2e`); method "
        "and analysis in [e2e.md](e2e.md). One-way latency in µs, full 2137-byte frames at 1 kHz, same "
        "frames and same writer QoS (`rsg_state_writer`) everywhere.",
        "",
        "| path | frames | lost | p50 | p90 | p99 | p99.9 | max | p50 / p99 at listener entry | publisher CPU | "
        "load avg (1 min) |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, title in LATENCY_ROWS:
        run = results.get(name)
        if not run:
            continue
        frames = run.get("received", run.get("round_trips"))
        load = (run.get("load_average") or {}).get("start", [None])[0]
        cpu = run.get("gateway", {}).get("cpu_percent", run.get("writer_cpu_percent", run.get("publisher_cpu_percent")))
        notified = run.get("reader_notified") or {}
        at_listener = (f"{fmt(notified['p50_us'])} / {fmt(notified['p99_us'])}"
                       if "p50_us" in notified and "p99_us" in notified else "–")
        lines.append(f"| {title} | {fmt(frames)} | {fmt(run.get('lost'))} | {fmt(run['p50_us'])} | "
                     f"{fmt(run['p90_us'])} | {fmt(run['p99_us'])} | {fmt(run.get('p99.9_us'))} | "
                     f"{fmt(run['max_us'])} | {at_listener} | {fmt(cpu) + ' %' if cpu is not None else '–'} | "
                     f"{fmt(load, 2)} |")
    lines += ["", "At listener entry: the same frames timed when the reader's listener is called, before "
              "`take()`; the latency columns time them after `take()`. The two differ most with data-sharing, "
              "where a reliable reader acknowledges inside `take()` (see latency_breakdown.md).",
              "", "Publisher CPU: the rsg_gateway process (gateway rows) or the plain writer process (Fast DDS "
              "rows), the relay process (floor rows), all threads, as % of one core over the measured part. The floor relays "
              "receive a datagram, copy the stamp out at a fixed offset and write it, with no validation, each "
              "written directly on its DDS API (Cyclone: default writer QoS, reliable keep-last 1; Fast DDS: the "
              "same, profile `bench_relay_writer`); the Cyclone reader is reliable keep-last 100 with a listener, "
              "like the bench's Fast DDS reader. The embedded row is the controller's callback in the process "
              "that also sends (like the UDP row's receiver thread). ddsperf reports percentiles per "
              "second; its row is their round-trip-weighted mean, halved (no p99.9). Its \"lost\" counts ping "
              "timeouts.", "", "## Goals", "",
              "| goal | measured | limit | result | detail |", "|---|---:|---:|:---:|---|"]
    for g in results["goals"]:
        lines.append(f"| {g['goal']} | {fmt(float(g['value']))} | {fmt(float(g['limit']))} | "
                     f"{'pass' if g['pass'] else '**miss**'} | {g['how']} |")
    lines += ros2_standard_section(results)
    for key, transport in (("max_rate", "UDP"), ("max_rate_datasharing", "data-sharing")):
        if key not in results:
            continue
        run = results[key]
        lines += ["", f"## Highest rate without loss, {transport}: {fmt(run['max_rate_zero_loss_hz'], 0)} Hz", "",
                  f"Gateway over {transport}, {run['step_duration_s']:.0f} s per step, stopping at the first step "
                  "that loses a frame or where the sender falls behind (below 95 % of the rate).", "",
                  "| rate | sender reached | lost | gateway received | gateway published | UDP buffer drops (host) "
                  "| p50 | p99 | gateway CPU |",
                  "|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
        for step in run["steps"]:
            stats = step.get("gateway_stats") or {}
            lines.append(f"| {fmt(step['rate_hz'], 0)} Hz | {fmt(step['achieved_rate_hz'], 0)} Hz | "
                         f"{fmt(step['lost'])} | {fmt(stats.get('frames_received'))} | "
                         f"{fmt(stats.get('frames_published'))} | {fmt(step.get('host_udp_receive_buffer_drops'))} | "
                         f"{fmt(step['p50_us'])} | {fmt(step['p99_us'])} | "
                         f"{fmt(step['gateway_cpu_percent'])} % |")
    if "soak" in results:
        soak = results["soak"]
        gateway = soak["gateway"]
        lines += ["", f"## Gateway memory and CPU over {soak['duration_s']:.0f} s at 1 kHz", "",
                  f"VmRSS {fmt(gateway['rss_kb_after_warmup'])} kB after warm-up, {fmt(gateway['rss_kb_end'])} kB "
                  f"at the end: growth {fmt(gateway['rss_growth_kb'])} kB; CPU {fmt(gateway['cpu_percent'], 2)} % "
                  f"of one core over the whole soak; {fmt(soak['lost'])} of {fmt(soak['sent'])} frames lost."
                  + (" The soak ran alongside the other runs (to fit the default time budget)."
                     if soak.get("concurrent_with_other_runs") else ""), "",
                  "| t (s) | VmRSS (kB) | CPU since previous sample (%) |", "|---:|---:|---:|"]
        timeline = gateway["timeline"]
        every = max(1, len(timeline) // 8)  # about 8 rows; the last one always
        for point in timeline[::every] + ([timeline[-1]] if (len(timeline) - 1) % every else []):
            lines.append(f"| {point['t_s']:.0f} | {fmt(point['rss_kb'])} | {fmt(point['cpu_percent'], 2)} |")
    lines += ["", "![latency CDF](latency_cdf.png)", ""]
    return "\n".join(lines)


def ros2_standard_section(results):
    """The standard ROS 2 topics' cost: the same gateway run with them off and on, side by side."""
    off, on = results.get("gateway_udp"), results.get("gateway_udp_ros2_standard")
    if not (off and on):
        return []
    received = on.get("ros2_standard_received", {})
    lines = ["", "## Standard ROS 2 topics: cost on the RobotState path", "",
             f"`--joint-states`, `--tf` and `--external-wrench` at {fmt(on.get('ros2_standard_hz'), 0)} Hz each "
             "(one reader of each in the bench; messages received: "
             + ", ".join(f"{name} {fmt(count)}" for name, count in received.items())
             + "), next to the same run without them.", "",
             "| standard topics | p50 | p99 | p99.9 | gateway CPU |", "|---|---:|---:|---:|---:|"]
    for label, run in (("off", off), ("on, 100 Hz each", on)):
        lines.append(f"| {label} | {fmt(run['p50_us'])} | {fmt(run['p99_us'])} | {fmt(run.get('p99.9_us'))} | "
                     f"{fmt(run['gateway']['cpu_percent'])} % |")
    return lines


def plot(run_dir, out_dir):
    """latency_cdf.png: CDF (linear fraction) and tail (1 - CDF, log) of every measured latency."""
    if not shutil.which("gnuplot"):
        print("e2e_report.py: gnuplot not found, no latency_cdf.png", file=sys.stderr)
        return
    curves = [(run_dir / f"{name}.cdf", title.replace("*", "")) for name, title in LATENCY_ROWS
              if (run_dir / f"{name}.cdf").exists()]
    if not curves:
        return
    # A gateway and its baseline share a colour; the baseline is dashed.
    styles = {"baseline_udp_oneway": "lc 1 dt 3", "baseline_fastdds": "lc 2 dt 2", "gateway_udp": "lc 2 dt 1",
              "baseline_fastdds_shm": "lc 3 dt 2", "gateway_shm": "lc 3 dt 1",
              "baseline_fastdds_datasharing": "lc 4 dt 2", "gateway_datasharing": "lc 4 dt 1",
              "embedded_callback": "lc 1 dt 1"}
    cdf = ", ".join(f"'{path}' using 1:2 with lines lw 2 {styles.get(path.stem, '')} title '{title}'"
                    for path, title in curves)
    tail = ", ".join(f"'{path}' using 1:(1-$2) with lines lw 2 {styles.get(path.stem, '')} notitle"
                     for path, _ in curves)
    script = f"""
set terminal pngcairo size 1400,600 font ',10'
set output '{out_dir / 'latency_cdf.png'}'
set multiplot layout 1,2 title 'rsg one-way latency at 1 kHz, 2137-byte frames'
set logscale x
set xlabel 'latency (us)'
set grid
set key bottom right
set ylabel 'fraction of frames at or below'
set yrange [0:1]
plot {cdf}
set logscale y
set yrange [1e-5:1]
set ylabel 'fraction of frames above (tail)'
plot {tail}
unset multiplot
"""
    subprocess.run(["gnuplot"], input=script, text=True, check=True)


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--render":
        # Only the table again, from a committed results.json (e.g. after a change of layout).
        out_dir = Path(sys.argv[2])
        results = read_json(out_dir / "results.json")
        (out_dir / "results.md").write_text(markdown(results), encoding="utf-8")
        return
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    run_dir, out_dir = Path(sys.argv[1]), Path(sys.argv[2])
    settings_file = run_dir / "settings.json"
    results = merge(load_runs(run_dir), read_json(settings_file) if settings_file.exists() else {})
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "results.json").write_text(json.dumps(results, indent=2) + "\n", encoding="utf-8")
    (out_dir / "results.md").write_text(markdown(results), encoding="utf-8")
    plot(run_dir, out_dir)
    print(markdown(results))


if __name__ == "__main__":
    main()
