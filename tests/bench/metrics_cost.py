"""What Prometheus scraping costs rsg_gateway at 1 kHz (issue 28: at most 0.2 % of a core).

    metrics_cost.py --bin BUILD/bin [--rounds 4] [--seconds 20] [--fast-interval 0.01] --out DIR

Side by side, in alternating order, `--rounds` times: a fresh rsg_gateway (--ros2 off, no reader)
taking a 1 kHz stream from rsg_sim (SCHED_FIFO where allowed), with
  off         no --metrics
  scraped_1s  --metrics, GET /metrics once a second (Prometheus' usual interval is longer)
  scraped_fast  --metrics, GET /metrics every --fast-interval seconds: the same work many times,
              so that the cost of one scrape stands out of the noise of a gateway's CPU
Measured over a window of --seconds once the stream runs: the gateway's CPU in percent of one core
(its threads' on-CPU time from /proc/PID/task/*/schedstat, nanoseconds) and the scrapes that
answered 200 (and those that failed, within the window). Reported: the median over the rounds of
scraped_1s - off (the side-by-side figure the issue asks for), and the cost of one scrape
((scraped_fast - off) / scrapes per second), times one scrape a second. Writes
DIR/metrics_cost.json and prints a table; ratios are within this one run. Timings only: no
pass/fail.
"""
import argparse
import http.client
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "readers"))
from harness import acquire_domain, free_udp_port, read_json, wait_for  # noqa: E402
from metrics_support import free_tcp_port  # noqa: E402
from readers import realtime_prefix, terminate  # noqa: E402

CONFIGS = ("off", "scraped_1s", "scraped_fast")


def on_cpu_ns(pid):
    """Time on a CPU of every thread of `pid` (the gateway's threads live as long as it does)."""
    total = 0
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            total += int((task / "schedstat").read_text().split()[0])
        except (FileNotFoundError, ProcessLookupError):
            pass
    return total


class Scraper(threading.Thread):
    """GET /metrics every `interval` seconds on one kept-alive connection (as Prometheus does),
    counting the answers that are 200 with rsg's metrics in them."""

    def __init__(self, port, interval):
        super().__init__(daemon=True)
        self.port, self.interval = port, interval
        self.ok = self.failed = 0
        self.stop = threading.Event()

    def run(self):
        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=5)
        next_at = time.monotonic()
        while not self.stop.is_set():
            try:
                connection.request("GET", "/metrics")
                response = connection.getresponse()
                body = response.read()
                if response.status == 200 and b"rsg_frames_published_total" in body:
                    self.ok += 1
                else:
                    self.failed += 1
            except (OSError, http.client.HTTPException):
                self.failed += 1
                connection.close()
                connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=5)
            next_at += self.interval
            self.stop.wait(max(0.0, next_at - time.monotonic()))
        connection.close()


def run_point(args, config, domain, scratch):
    port, metrics = free_udp_port(), free_tcp_port()
    stats = scratch / f"{config}.stats.json"
    log = open(scratch / f"{config}.gateway.log", "w")
    flags = [] if config == "off" else ["--metrics", f"127.0.0.1:{metrics}"]
    gateway = subprocess.Popen([str(Path(args.bin) / "rsg_gateway"), "--listen", f"127.0.0.1:{port}", "--domain",
                                str(domain), "--expected-rate", "1000", "--stats-file", str(stats), *flags],
                               stdout=log, stderr=log)
    sim = scraper = None
    try:
        wait_for(lambda: read_json(stats), "the gateway to start")
        sim = subprocess.Popen([*realtime_prefix(), str(Path(args.bin) / "rsg_sim"), "--to", f"127.0.0.1:{port}",
                                "--rate", "1000", "--duration", str(args.seconds + 6)],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if config != "off":
            scraper = Scraper(metrics, 1.0 if config == "scraped_1s" else args.fast_interval)
            scraper.start()  # its first tries may find the endpoint not yet bound: counted outside the window
        time.sleep(3)  # the stream settles
        before, ok0, failed0 = read_json(stats), scraper.ok if scraper else 0, scraper.failed if scraper else 0
        c0, t0 = on_cpu_ns(gateway.pid), time.monotonic()
        time.sleep(args.seconds)
        c1, t1 = on_cpu_ns(gateway.pid), time.monotonic()
        after, ok1, failed1 = read_json(stats), scraper.ok if scraper else 0, scraper.failed if scraper else 0
        alive = gateway.poll() is None
    finally:
        if scraper:
            scraper.stop.set()
            scraper.join(timeout=10)
        terminate(sim, gateway, timeout_s=30)
        log.close()
    seconds = t1 - t0
    return {"config": config, "seconds": round(seconds, 2), "gateway_alive": alive,
            "gateway_cpu_pct": round(100.0 * (c1 - c0) / 1e9 / seconds, 3),
            "published_per_s": round((after["frames_published"] - before["frames_published"]) / seconds, 1),
            "scrapes_per_s": round((ok1 - ok0) / seconds, 2), "failed_scrapes": failed1 - failed0}


def summary(points):
    by = {config: [p for p in points if p["config"] == config] for config in CONFIGS}
    cpu = {config: statistics.median(p["gateway_cpu_pct"] for p in by[config]) for config in CONFIGS}
    # Paired by round (each round runs the three back to back), then the median of the differences.
    side_by_side = statistics.median(s["gateway_cpu_pct"] - o["gateway_cpu_pct"]
                                     for o, s in zip(by["off"], by["scraped_1s"]))
    per_scrape = statistics.median((f["gateway_cpu_pct"] - o["gateway_cpu_pct"]) / f["scrapes_per_s"]
                                   for o, f in zip(by["off"], by["scraped_fast"]) if f["scrapes_per_s"])
    return {"median_cpu_pct": cpu, "scraped_1s_minus_off_pct": round(side_by_side, 3),
            "one_scrape_per_s_pct": round(per_scrape, 4),
            "fast_scrapes_per_s": statistics.median(p["scrapes_per_s"] for p in by["scraped_fast"])}


def table(result):
    s = result["summary"]
    lines = [f"### rsg_gateway at 1 kHz, /metrics scraped vs off, on {result['cpu']} ({result['cores']} cores), "
             f"{result['rounds']} rounds of {result['seconds']:.0f} s", "",
             "| round | config | gateway CPU % of a core | published/s | scrapes/s | failed scrapes |",
             "|---|---|---|---|---|---|"]
    for p in result["points"]:
        lines.append(f"| {p['round']} | {p['config']} | {p['gateway_cpu_pct']} | {p['published_per_s']} | "
                     f"{p['scrapes_per_s']} | {p['failed_scrapes']} |")
    lines += ["", f"- side by side, scraped once a second minus off (median of the rounds' differences): "
              f"**{s['scraped_1s_minus_off_pct']} % of a core**",
              f"- one scrape a second, from {s['fast_scrapes_per_s']} scrapes/s: "
              f"**{s['one_scrape_per_s_pct']} % of a core** ((scraped_fast - off) / scrapes per second)"]
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--bin", required=True)
    parser.add_argument("--rounds", type=int, default=4)
    parser.add_argument("--seconds", type=float, default=20)
    parser.add_argument("--fast-interval", type=float, default=0.01)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    domain = acquire_domain()
    points = []
    with tempfile.TemporaryDirectory(prefix="rsg_bench_metrics_") as tmp:
        for round_ in range(1, args.rounds + 1):
            # Alternate the order, so that a drift of the host's load does not favour one config.
            for config in (CONFIGS if round_ % 2 else tuple(reversed(CONFIGS))):
                point = {"round": round_, **run_point(args, config, domain, Path(tmp))}
                points.append(point)
                print(json.dumps(point), flush=True)
    cpu_model = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name")), "?")
    result = {"cpu": cpu_model, "cores": os.cpu_count(), "rounds": args.rounds, "seconds": args.seconds,
              "load_average_at_end": os.getloadavg(), "points": points}
    result["summary"] = summary(points)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "metrics_cost.json").write_text(json.dumps(result, indent=2) + "\n")
    print(table(result))


if __name__ == "__main__":
    main()
