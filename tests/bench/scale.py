"""`make bench` scale suite: how rsg's cost grows with robots and with remote readers.

    scale.py --bin BUILD/bin --out DIR [--seconds 8] [--points 1,4,8,16] [--discovery-server]
             [--series robots,readers,readers_multicast] [--receive-off-sender]

Runs on the network-namespace bed of tests/net (netbed.py): robots on `robot`, gateways on
`gw`, readers on `ops1`/`ops2`, so every reader is remote (UDP over a veth bridge, MTU 1500).

  robots N:  N x (robot 1 kHz full frames -> own rsg_gateway, partition robotK -> one reader)
  readers M: one robot + rsg_gateway -> M readers (half on ops1, half on ops2)
  readers_multicast M: the same with readers of rsg_participant_multicast (xml_profiles/rsg.xml):
             the gateway sends one datagram per sample to their group instead of one per reader
             (not in the default --series: `make bench` runs robots and readers)

Robots and readers are rsg_bench_scale_probe (scale_probe.cpp): the robot sends the e2e suite's
stamped full frames (index and CLOCK_MONOTONIC send time in the frame), each reader stamps every
sample on arrival. The namespaces share the host's clock, so p50/p99 latency per point is the
robot's send to the remote reader's receive, over the frames sent inside the window, pooled over
every reader (and the worst reader's p99 on its own).

Per point, over a window after a warm-up: gateway CPU (utime+stime from /proc, % of one core;
total and per robot), gateway RSS, whole-host CPU (/proc/stat, cores busy), each gateway's
published rate, and the time from launching the gateways (robots already streaming) to the
first sample at every robot's first-sample probe (the first line of rsg_echo --json --count 1,
started with the gateways). With --discovery-server every participant is a client of
`fastdds discovery` on gw.

Readers use rsg_echo's table-mode QoS (reader_realtime: best effort), so the gateway serves them
as it serves a monitoring consumer; they print nothing, so what "all rsg processes" adds per reader
is a lean reader, not rsg_echo's table. A point is marked machine-limited ("rate") when a gateway
published less than 98 % of 1 kHz (such points are left out of the slopes), and "CPU" when the
host's cores were 95 % busy or more over the window: then latency includes waiting for a core
(behind the bed's own processes or anyone else's) and says more about the machine than about rsg.
The table's "others" is the host's busy time minus the bed's processes': the kernel's network work
for the bed's traffic (softirq time, not charged to the processes; it grows with the traffic) plus
any other work on a shared machine, which a quiet run does not have. It is approximate: /proc/stat
is sampled on the scheduler tick, and at low load it can read below the bed's own CPU (shown as 0).
With --receive-off-sender the bridge takes in what `gw` sends on a kernel thread (netbed.NetBed
off_sender), so the gateways' CPU no longer includes the forwarding and the readers' receiving,
which a veth otherwise runs inside the gateway's sendmsg and a NIC leaves to the readers' machines.
Whole-host CPU (/proc/stat) is reported as context only: on a shared machine
it measures everyone; the CPU of every process of the bed (robots, gateways, readers, server) is
what rsg costs.
Before each point the suite waits (up to --quiet-wait s) for the host to be 85 % idle, so that a
shared machine's other work lands between points rather than in them; each row records the wait
(-1: never quiet).
Writes DIR/scale.json, DIR/scale.md (the table) and gnuplot PNGs.
"""

import argparse
import json
import os
import signal
import subprocess
import tempfile
import threading
import time
from pathlib import Path

from netbed import HOSTS, NetBed, discovery_server_argv  # noqa: E402

from test_domain import acquire_domain  # noqa: E402

RAW_PORT = 17000
DS_PORT = 11811
PAGE = os.sysconf("SC_PAGE_SIZE")
SATURATED = 0.95  # host busy fraction from which a point's latency is the machine's (see above)
TICK = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid):
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICK


def rss_kib(pid):
    return int(Path(f"/proc/{pid}/statm").read_text().split()[1]) * PAGE // 1024


def host_busy():
    """(busy, total) jiffies of all CPUs."""
    values = [int(v) for v in Path("/proc/stat").read_text().splitlines()[0].split()[1:]]
    idle = values[3] + values[4]
    return sum(values) - idle, sum(values)


def cpu_model():
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "unknown"


def read_json(path):
    """A gateway's stats file; retried while the gateway rewrites it."""
    for _ in range(100):
        try:
            return json.loads(Path(path).read_text())
        except (OSError, json.JSONDecodeError):
            time.sleep(0.02)
    raise RuntimeError(f"cannot read {path}")


class Point:
    """One measured configuration: `robots` gateways, `readers` readers per gateway."""

    def __init__(self, args, bed, scratch, robots, readers, participant_profile="rsg_participant"):
        self.args, self.bed, self.dir = args, bed, Path(scratch)
        self.robots, self.readers = robots, readers
        self.participant_profile = participant_profile
        self.domain = acquire_domain()
        self.processes = []
        self.discovery = ["--discovery-server", f"{HOSTS['gw']}:{DS_PORT}"] if args.discovery_server else []

    def start(self, host, label, argv, stdout=None):
        process = self.bed.start(host, label, [str(a) for a in argv], self.dir, stdout=stdout)
        self.processes.append(process)
        return process

    def window(self, gateways):
        """The measured part: the bed runs for --seconds (a profiler can take this over)."""
        time.sleep(self.args.seconds)

    def measure(self):
        b = Path(self.args.bin)
        t = Path(self.args.test_bin) if self.args.test_bin else b.parent / "tests" / "bin"
        if self.args.discovery_server:
            self.start("gw", "ds", discovery_server_argv(DS_PORT))
        for k in range(self.robots):  # the robots stream before there is a gateway, as on a plant restart
            self.start("robot", f"robot{k}", [t / "rsg_bench_scale_probe", "send", "--to",
                                              f"{HOSTS['gw']}:{RAW_PORT + k}", "--rate", 1000,
                                              "--duration", self.args.seconds + 60])
        launched = time.monotonic()
        gateways, stats = [], []
        for k in range(self.robots):
            stats.append(self.dir / f"gw{k}.json")
            gateways.append(self.start("gw", f"gw{k}", [b / "rsg_gateway", "--domain", self.domain, "--listen",
                                                        f"{HOSTS['gw']}:{RAW_PORT + k}", "--partition", f"robot{k}",
                                                        "--stats-file", stats[-1], *self.discovery]))
        probes = [self.start("ops1", f"probe{k}", [b / "rsg_echo", "--domain", self.domain, "--partition",
                                                   f"robot{k}", "--json", "--count", 1, "--timeout", 30,
                                                   *self.discovery], stdout=subprocess.PIPE)
                  for k in range(self.robots)]
        # The first sample is the probe's first line, not its exit: a Fast DDS process sleeps 100 ms
        # while it shuts down (DomainParticipantFactory's destructor), and 16 of them shut down at once.
        first = [float("nan")] * self.robots

        def first_line(k):
            if probes[k].stdout.readline():
                first[k] = time.monotonic() - launched

        readers = [threading.Thread(target=first_line, args=(k,)) for k in range(self.robots)]
        for reader in readers:
            reader.start()
        for reader, probe in zip(readers, probes):
            reader.join(timeout=40)
            probe.wait(timeout=40)
        arrivals = []
        capacity = int((self.args.warmup + self.args.seconds + 30) * 1000)  # samples a reader may get
        for k in range(self.robots):
            for r in range(self.readers):
                arrivals.append(self.dir / f"arrivals{k}_{r}.txt")
                self.start("ops1" if r % 2 == 0 else "ops2", f"reader{k}_{r}",
                           [t / "rsg_bench_scale_probe", "read", "--domain", self.domain, "--partition",
                            f"robot{k}", "--out", arrivals[-1], "--capacity", capacity,
                            "--participant-profile", self.participant_profile, *self.discovery])
        time.sleep(self.args.warmup)
        running = [p for p in self.processes if p.poll() is None]
        cpu0 = [cpu_seconds(g.pid) for g in gateways]
        bed0 = sum(cpu_seconds(p.pid) for p in running)
        host0, wall0, window0 = host_busy(), time.monotonic(), time.monotonic_ns()
        published0 = [read_json(s)["frames_published"] for s in stats]
        self.window(gateways)
        cpu1 = [cpu_seconds(g.pid) for g in gateways]
        bed1 = sum(cpu_seconds(p.pid) for p in running)
        host1, wall1, window1 = host_busy(), time.monotonic(), time.monotonic_ns()
        published1 = [read_json(s)["frames_published"] for s in stats]
        readers = [read_json(s)["state_readers"] for s in stats]
        rss = [rss_kib(g.pid) for g in gateways]
        for process in reversed(self.processes):
            if process.poll() is None:
                process.send_signal(signal.SIGTERM)
        for process in self.processes:
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                process.kill()
        wall = wall1 - wall0
        gateway_cpu = sum(c1 - c0 for c0, c1 in zip(cpu0, cpu1)) / wall * 100
        rates = [(p1 - p0) / wall for p0, p1 in zip(published0, published1)]
        busy = (host1[0] - host0[0]) / max(1, host1[1] - host0[1])
        latency = latency_summary(arrivals, window0, window1)
        return {
            "robots": self.robots, "readers_per_gateway": self.readers,
            "matched_readers_min": min(readers),
            "first_sample_s_max": max(first), "first_sample_s_median": sorted(first)[len(first) // 2],
            "gateway_cpu_pct_total": gateway_cpu, "gateway_cpu_pct_per_gateway": gateway_cpu / self.robots,
            "gateway_rss_kib_mean": sum(rss) / len(rss), "gateway_rss_kib_max": max(rss),
            "rate_hz_min": min(rates), "bed_cpu_pct": (bed1 - bed0) / wall * 100,
            "host_busy_fraction": busy, "host_cores_busy": busy * os.cpu_count(),
            "machine_limited": min(rates) < 980, **latency,
        }


def percentile(values, fraction):
    """Nearest-rank percentile of sorted `values`."""
    return values[min(len(values) - 1, max(0, round(fraction * len(values)) - 1))] if values else float("nan")


def latency_summary(files, window0_ns, window1_ns):
    """Send-to-receive latency of the frames sent inside the window, at every reader: p50 and p99
    over all of them, the worst reader's p99, and the frames a reader missed (index gaps).

    Each file holds a probe reader's "index sent_ns received_ns" lines (CLOCK_MONOTONIC of the
    host, which every namespace shares)."""
    pooled, worst_p99, missed, received = [], 0.0, 0, 0
    for path in files:
        mine, indices = [], set()
        for line in Path(path).read_text().splitlines():
            index, sent, got = map(int, line.split())
            if window0_ns <= sent < window1_ns:
                mine.append((got - sent) / 1000)
                indices.add(index)
        if indices:
            missed += max(indices) - min(indices) + 1 - len(indices)
        received += len(mine)
        mine.sort()
        worst_p99 = max(worst_p99, percentile(mine, 0.99))
        pooled += mine
    pooled.sort()
    return {"latency_us_p50": percentile(pooled, 0.50), "latency_us_p99": percentile(pooled, 0.99),
            "latency_us_p99_worst_reader": worst_p99, "latency_us_max": pooled[-1] if pooled else float("nan"),
            "latency_samples": received, "latency_missed": missed}


def wait_for_quiet(limit_s, idle=0.85, period_s=3.0):
    """On a shared machine: waits until the host's cores were at least `idle` idle over `period_s`
    (others' builds and tests finished), at most `limit_s`; returns the seconds waited (-1: never
    quiet, the point runs anyway)."""
    start = time.monotonic()
    while True:
        busy0 = host_busy()
        time.sleep(period_s)
        busy1 = host_busy()
        if 1 - (busy1[0] - busy0[0]) / max(1, busy1[1] - busy0[1]) >= idle:
            return time.monotonic() - start
        if time.monotonic() - start >= limit_s:
            return -1.0


def fit_slope(xs, ys):
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    den = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / den if den else 0.0


def plot(out, name, rows, x_key, x_label):
    data = out / f"{name}.dat"
    data.write_text("".join(f"{r[x_key]} {r['gateway_cpu_pct_total']:.2f} {r['gateway_cpu_pct_per_gateway']:.2f} "
                            f"{r['gateway_rss_kib_mean'] / 1024:.2f} {r['bed_cpu_pct']:.1f} "
                            f"{r['first_sample_s_max']:.3f} {r['latency_us_p50']:.0f} {r['latency_us_p99']:.0f} "
                            f"{r['latency_us_p99_worst_reader']:.0f} {r['host_busy_fraction'] * 100:.0f}\n"
                            for r in rows))
    script = f"""
set terminal pngcairo size 1200,1200
set output '{out / (name + ".png")}'
set multiplot layout 3,2 title 'rsg scale: {x_label} ({cpu_model()}, 2 cores shared)'
set xlabel '{x_label}'
set grid
set key left top
plot '{data}' using 1:2 with linespoints title 'gateway CPU, % of a core (all gateways)', \
     '{data}' using 1:3 with linespoints title 'per gateway'
plot '{data}' using 1:4 with linespoints title 'gateway RSS, MiB (mean)'
plot '{data}' using 1:5 with linespoints title 'all rsg processes (robots, gateways, readers), % of a core'
plot '{data}' using 1:6 with linespoints title 'time to first sample, s (slowest)'
set logscale y
plot '{data}' using 1:7 with linespoints title 'latency p50, us (send to remote reader)', \
     '{data}' using 1:8 with linespoints title 'p99, all readers', \
     '{data}' using 1:9 with linespoints title 'p99, worst reader'
unset logscale y
set yrange [0:105]
set key right bottom
plot '{data}' using 1:10 with linespoints title 'host busy, % of all cores (anyone)'
unset multiplot
"""
    subprocess.run(["gnuplot"], input=script, text=True, check=True)


def table(rows, x_key):
    head = (f"| {x_key} | first sample (slowest / median) s | gateway CPU % (total / per gateway) | "
            f"gateway RSS MiB | min rate Hz | latency p50 / p99 us (worst reader p99) | all rsg processes CPU % | "
            f"host busy % (others, % of a core) | machine-limited |\n"
            f"|---|---|---|---|---|---|---|---|---|\n")
    return head + "".join(
        f"| {r[x_key]} | {r['first_sample_s_max']:.2f} / {r['first_sample_s_median']:.2f} | "
        f"{r['gateway_cpu_pct_total']:.1f} / {r['gateway_cpu_pct_per_gateway']:.1f} | "
        f"{r['gateway_rss_kib_mean'] / 1024:.1f} | {r['rate_hz_min']:.0f} | "
        f"{r['latency_us_p50']:.0f} / {r['latency_us_p99']:.0f} ({r['latency_us_p99_worst_reader']:.0f}) | "
        f"{r['bed_cpu_pct']:.0f} | "
        f"{r['host_busy_fraction'] * 100:.0f} ({others_cpu_pct(r):.0f}) | "
        f"{limit(r)} |\n" for r in rows)


SERIES = {  # name: (x key, plot label, table heading, participant profile of the readers)
    "robots": ("robots", "robots N (robot + gateway + reader each)", "N robots", "rsg_participant"),
    "readers": ("readers_per_gateway", "remote readers M of one gateway", "M remote readers of one gateway",
                "rsg_participant"),
    "readers_multicast": ("readers_per_gateway", "remote multicast readers M of one gateway",
                          "M remote multicast readers of one gateway (rsg_participant_multicast)",
                          "rsg_participant_multicast"),
}


def render(out, results):
    """Slopes (over the points the machine did not limit), table, plots, for the series that ran."""
    ran = [name for name in SERIES if results.get(name)]
    sections, slopes = [], []
    for name in ran:
        x_key, x_label, heading, _ = SERIES[name]
        rows, unit = results[name], "robot" if name == "robots" else "reader"
        suffix = name.removeprefix("readers").removeprefix("robots")  # "" or "_multicast"
        gateway = fit_slope([r[x_key] for r in free(rows)], [r["gateway_cpu_pct_total"] for r in free(rows)])
        bed = fit_slope([r[x_key] for r in free(rows)], [r["bed_cpu_pct"] for r in free(rows)])
        results[f"slope_gateway_cpu_pct_per_{unit}{suffix}"] = gateway
        results[f"slope_bed_cpu_pct_per_{unit}{suffix}"] = bed
        plot(out, f"scale_{name}", rows, x_key, x_label)
        sections.append(f"## {heading}\n\n{table(rows, x_key)}\n")
        slopes.append(f"{name}: gateway CPU {gateway:.2f} % of a core per {unit}, all rsg processes {bed:.1f} % "
                      f"per {unit}; latency p50 / p99 us: {growth(rows, x_key)}")
    (out / "scale.json").write_text(json.dumps(results, indent=1) + "\n")
    text = (f"# Scale suite ({results['cpu']}, {results['cores']} cores, {results['seconds']:.0f} s windows, "
            f"discovery server: {results['discovery_server']}, load average before {results['load_before'][0]:.1f})\n\n"
            + ("What the gateways send is forwarded and delivered on a kernel thread (--receive-off-sender): "
               "their CPU is their own send, not the readers' receiving.\n\n"
               if results.get("receive_off_sender") else
               "Plain veth: the forwarding and the readers' receiving run inside the gateways' sendmsg and "
               "count as their CPU.\n\n")
            + "".join(sections)
            + "Least-squares slopes over the points not machine-limited (over all of them where fewer than "
              "two were not), and latency from the robot's send to the remote reader's receive:\n\n"
            + "".join(f"- {line}\n" for line in slopes))
    (out / "scale.md").write_text(text)
    print(text)


def others_cpu_pct(row):
    """Host busy time not charged to the bed's processes: kernel networking, and anyone else."""
    return max(0.0, row["host_cores_busy"] * 100 - row["bed_cpu_pct"])


def limit(row):
    return "rate" if row["machine_limited"] else "CPU" if row["host_busy_fraction"] >= SATURATED else "no"


def growth(rows, x_key):
    return ", ".join(f"{r['latency_us_p50']:.0f} / {r['latency_us_p99']:.0f} at {x_key.split('_')[0]} {r[x_key]}"
                     + (f" ({limit(r)}-limited)" if limit(r) != "no" else "") for r in rows)


def free(rows):
    """The points the machine did not limit, for the slopes; all of them when fewer than two are left
    (the table says which were limited)."""
    unlimited = [r for r in rows if limit(r) == "no"]
    return unlimited if len(unlimited) >= 2 else rows


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", required=True)
    parser.add_argument("--test-bin", help="directory of the bench's helpers (default: BIN/../tests/bin, the build "
                                           "tree's: CONTRIBUTING.md, \"Build tree\")")
    parser.add_argument("--out", required=True)
    parser.add_argument("--seconds", type=float, default=8.0)
    parser.add_argument("--warmup", type=float, default=2.0)
    parser.add_argument("--points", default="1,4,8,16")
    parser.add_argument("--discovery-server", action="store_true")
    parser.add_argument("--receive-off-sender", action="store_true",
                        help="what the gateways send is forwarded and delivered on a kernel thread, not "
                             "inside their sendmsg (netbed.NetBed off_sender): their CPU is then their own")
    parser.add_argument("--series", default="robots,readers",
                        help="comma-separated, in order, from: " + ", ".join(SERIES))
    parser.add_argument("--quiet-wait", type=float, default=120.0,
                        help="before each point, wait up to this many seconds for the host to be idle")
    parser.add_argument("--render", help="only redo the table and plots of OUT/scale.json")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.render:
        render(out, json.loads(Path(args.render).read_text()))
        return
    points = [int(p) for p in args.points.split(",")]
    series = args.series.split(",")
    unknown = [name for name in series if name not in SERIES]
    if unknown:
        parser.error(f"--series: unknown {', '.join(unknown)} (known: {', '.join(SERIES)})")
    results = {"cpu": cpu_model(), "cores": os.cpu_count(), "seconds": args.seconds,
               "discovery_server": args.discovery_server, "receive_off_sender": args.receive_off_sender,
               "load_before": os.getloadavg(),
               **{name: [] for name in series}}
    with NetBed(off_sender=("gw",) if args.receive_off_sender else ()) as bed:
        for sweep, x in [(name, n) for name in series for n in points]:
            quiet_after = wait_for_quiet(args.quiet_wait)
            with tempfile.TemporaryDirectory(prefix="rsg_scale_") as scratch:
                row = Point(args, bed, scratch, robots=x if sweep == "robots" else 1,
                            readers=1 if sweep == "robots" else x,
                            participant_profile=SERIES[sweep][3]).measure()
            row["waited_for_quiet_s"] = quiet_after
            print(f"{sweep} {x}: {json.dumps(row)}", flush=True)
            results[sweep].append(row)
    render(out, results)


if __name__ == "__main__":
    main()
