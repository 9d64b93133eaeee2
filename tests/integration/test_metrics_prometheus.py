"""--metrics, judged by the real Prometheus tools: `promtool check metrics` accepts the scrape, a real
Prometheus server scraping every second reports the published-frame counter equal to the valid
frames rsg_sim sent and the invalid counter per category equal to the invalid ones, the ingress
delay histogram counts every valid frame, /healthz and /readyz are 200 while the robot streams and
503 before and after, /livez 200 throughout, and every expression of the Grafana dashboard
evaluates on that server. Fails (never skips) when promtool or prometheus is missing."""

import json
import subprocess
import sys
import time
import urllib.parse
import urllib.request
from pathlib import Path

from dashboard_support import dashboard_expressions
from harness import check, main, read_json, wait_for, wait_for_stats
from metrics_support import free_tcp_port, http_get, parse_samples, require_tool, start_gateway, value_of

COUNT = 2001  # 4 s at 500 Hz: long enough to see /healthz 200 while it streams
CORRUPT_EVERY = 4
RATE = "500"
NAME = "robot1"


def query(port, promql):
    """The result vector of an instant query on Prometheus' HTTP API."""
    url = f"http://127.0.0.1:{port}/api/v1/query?" + urllib.parse.urlencode({"query": promql})
    with urllib.request.urlopen(url, timeout=5) as response:
        answer = json.load(response)
    check(answer["status"] == "success", f"Prometheus refused {promql!r}: {answer}")
    return answer["data"]["result"]


def start_prometheus(h, target_port):
    prometheus = require_tool("prometheus")
    port = free_tcp_port()
    config = h.dir / "prometheus.yml"
    config.write_text(
        "global:\n  scrape_interval: 1s\n  evaluation_interval: 1s\n"
        "scrape_configs:\n  - job_name: rsg\n    static_configs:\n"
        f"      - targets: ['127.0.0.1:{target_port}']\n")
    process = h.start("prometheus", [prometheus, f"--config.file={config}", f"--storage.tsdb.path={h.dir / 'tsdb'}",
                                     f"--web.listen-address=127.0.0.1:{port}", "--log.level=warn"])

    def ready():
        check(process.poll() is None, f"prometheus exited {process.poll()}")
        answer = http_get(port, "/-/ready")
        return answer and answer[0] == 200
    wait_for(ready, "Prometheus to be ready", timeout_s=30)
    return port


def body(h):
    promtool = require_tool("promtool")
    gateway, stats, udp, metrics = start_gateway(h, "gateway", "--name", NAME, rate=RATE)
    prometheus = start_prometheus(h, metrics)
    wait_for(lambda: query(prometheus, 'up{job="rsg"} == 1'), "Prometheus to scrape the gateway once")

    for path in ("/healthz", "/readyz"):
        status, text = http_get(metrics, path)
        check(status == 503, f"{path} answered {status} before any frame (expected 503: the link is down)")
    status, text = http_get(metrics, "/livez")
    check(status == 200, f"/livez answered {status} before any frame (expected 200: waiting for the robot is alive)")

    record, report_path = h.dir / "sim.record.jsonl", h.dir / "sim.report.json"
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{udp}", "--rate", RATE, "--count", str(COUNT),
                          "--corrupt-every", str(CORRUPT_EVERY), "--report", str(report_path)])
    # (c) 200 while frames arrive
    wait_for(lambda: sim.poll() is not None or (http_get(metrics, "/healthz") or (0,))[0] == 200,
             "/healthz 200 while the robot streams")
    check(sim.poll() is None, "the robot stopped before /healthz said 200")
    check(h.wait("sim", sim, 30) == 0, "rsg_sim failed")
    report = read_json(report_path)
    final = wait_for_stats(stats, lambda s: s["frames_received"] >= report["sent"], "the gateway to count every datagram")
    check(final["frames_published"] == report["valid"], f"published {final['frames_published']} of {report['valid']}")
    # ... and 503 once it stopped
    wait_for(lambda: (http_get(metrics, "/healthz") or (0,))[0] == 503, "/healthz 503 after the robot stopped")
    check(http_get(metrics, "/readyz")[0] == 503 and http_get(metrics, "/livez")[0] == 200,
          "after the robot stopped: /readyz not 503, or /livez not 200")

    # (a) promtool accepts the scrape, lint included, and the scrape says what the sim sent
    status, text = http_get(metrics, "/metrics")
    check(status == 200, f"/metrics answered {status}")
    (h.dir / "scrape.txt").write_text(text)
    lint = subprocess.run([promtool, "check", "metrics"], input=text, capture_output=True, text=True, timeout=30)
    check(lint.returncode == 0 and not lint.stdout.strip() and not lint.stderr.strip(),
          f"promtool check metrics (exit {lint.returncode}): {lint.stdout}{lint.stderr}")
    samples = parse_samples(text)
    check(value_of(samples, "rsg_frames_published_total", gateway=NAME) == report["valid"], "scrape: published")
    check(value_of(samples, "rsg_frames_received_total", gateway=NAME) == report["sent"], "scrape: received")
    for category, count in report["invalid"].items():
        check(value_of(samples, "rsg_frames_invalid_total", gateway=NAME, category=category) == count,
              f"scrape: invalid {category}")
    # The histograms count every valid frame, the +Inf bucket as many as _count.
    for histogram in ("rsg_ingress_delay_seconds", "rsg_frame_age_seconds"):
        count = value_of(samples, f"{histogram}_count", gateway=NAME)
        check(value_of(samples, f"{histogram}_bucket", gateway=NAME, le="+Inf") == count, f"{histogram}: +Inf != count")
    check(value_of(samples, "rsg_ingress_delay_seconds_count", gateway=NAME) == report["valid"],
          "scrape: the ingress delay histogram did not count every valid frame")

    # (b) the real server's view, through its HTTP API, once a scrape after the last frame is in
    def counter(promql):
        result = query(prometheus, promql)
        return {tuple(sorted(r["metric"].items())): float(r["value"][1]) for r in result}
    wait_for(lambda: list(counter(f'rsg_frames_published_total{{gateway="{NAME}"}}').values()) == [report["valid"]],
             f"Prometheus to report {report['valid']} published frames", timeout_s=30)
    invalid = {dict(labels)["category"]: value
               for labels, value in counter(f'rsg_frames_invalid_total{{gateway="{NAME}"}}').items()}
    check(invalid == {category: float(count) for category, count in report["invalid"].items()},
          f"Prometheus: invalid by category {invalid} != sent {report['invalid']}")
    check(sum(report["invalid"].values()) > 0, "the sim sent no invalid frame: the test proves nothing")

    # Every expression of the Grafana dashboard is PromQL Prometheus accepts, and finds a series.
    for expression in dashboard_expressions(for_prometheus=True):
        check(query(prometheus, expression), f"the dashboard's {expression!r} finds no series")

    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("metrics_prometheus", body))
