"""An attacker on the network against --metrics, with the default limits (docs/security.md, "What an
attacker on the network can and cannot do"): 40 slowloris connections (a request line, then a header
byte a second, never the end) from 5 addresses, each renewed as soon as the gateway closes it, and
32 keep-alive clients asking /metrics every 3 s, for 10 s. Meanwhile a health probe (a fresh
connection, GET /healthz, 2 s to answer, as the container's HEALTHCHECK) every half second is answered
every time, the limits are counted on /metrics (rsg_http_connections_closed_total, which promtool
accepts) and logged once each, the connections open never pass the limit, the gateway publishes
every frame rsg_sim sends, and its memory is what it was.

Loopback only: the attackers bind 127.0.0.20-24 (other clients to the gateway) and 127.0.0.1 (the
probe's own address, for the keep-alive clients). Fails on a gateway without the limits: the
slowloris connections fill its 32 slots and the probes go unanswered."""

import http.client
import socket
import subprocess
import sys
import threading
import time

from harness import check, main, read_json, wait_for, wait_for_stats
from metrics_support import http_get, parse_samples, require_tool, start_gateway, value_of

ATTACK_S = 10
PROBES = 20
RATE = 100


def rss_kb(pid):
    with open(f"/proc/{pid}/status") as status:
        return next(int(line.split()[1]) for line in status if line.startswith("VmRSS:"))


class Attacker(threading.Thread):
    """Runs `round(port, source)` again and again (a new connection each time) until stopped."""

    def __init__(self, port, source, round_):
        super().__init__(daemon=True)
        self.port, self.source, self.round, self.stopping, self.rounds = port, source, round_, False, 0

    def run(self):
        while not self.stopping:
            try:
                self.round(self)
            except (OSError, http.client.HTTPException):
                pass
            self.rounds += 1
            time.sleep(0.1)  # renewed as it closes, not in a busy loop of its own


def stop_all(attackers):
    for attacker in attackers:
        attacker.stopping = True
    for attacker in attackers:
        attacker.join(timeout=15)


def slowloris(attacker):
    with socket.create_connection(("127.0.0.1", attacker.port), timeout=5,
                                  source_address=(attacker.source, 0)) as client:
        client.sendall(b"GET /metrics HTTP/1.1\r\nHost: x\r\n")
        while not attacker.stopping:
            client.sendall(b"X")
            client.settimeout(1.0)
            try:
                if client.recv(4096) == b"":
                    return  # closed by the gateway: renew
            except socket.timeout:
                pass


def keep_alive(attacker):
    connection = http.client.HTTPConnection("127.0.0.1", attacker.port, timeout=5,
                                            source_address=(attacker.source, 0))
    try:
        while not attacker.stopping:
            connection.request("GET", "/metrics")
            connection.getresponse().read()
            for _ in range(30):  # 3 s
                if attacker.stopping:
                    return
                time.sleep(0.1)
    finally:
        connection.close()


def probe(port):
    """What a health check sees: the status, or None when nothing answered within 2 s."""
    answer = http_get(port, "/healthz", timeout_s=2.0)
    return None if answer is None else answer[0]


def body(h):
    promtool = require_tool("promtool")
    count = RATE * (ATTACK_S + 4)
    gateway, stats, udp, metrics = start_gateway(h, "gateway", rate=str(RATE))
    report_path = h.dir / "sim.report.json"
    sim = h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{udp}", "--rate", str(RATE), "--count",
                          str(count), "--report", str(report_path)])
    wait_for(lambda: probe(metrics) == 200, "/healthz to say the link is up")
    rss_before = rss_kb(gateway.pid)

    attackers = [Attacker(metrics, f"127.0.0.{20 + i % 5}", slowloris) for i in range(40)]
    attackers += [Attacker(metrics, "127.0.0.1", keep_alive) for _ in range(32)]
    for attacker in attackers:
        attacker.start()
    time.sleep(1.0)  # the slots are full
    answers, open_seen = [], []
    deadline = time.monotonic() + ATTACK_S - 1
    while len(answers) < PROBES and time.monotonic() < deadline + 5:
        started = time.monotonic()
        answers.append(probe(metrics))
        time.sleep(max(0.0, 0.5 - (time.monotonic() - started)))
    # The server's own count of open connections, read through the same limits.
    scrape = http_get(metrics, "/metrics", timeout_s=2.0)
    stop_all(attackers)
    print(f"[{h.name}] probes: {answers}; attack rounds: {sum(a.rounds for a in attackers)}", flush=True)
    check(answers.count(200) == PROBES, f"{PROBES - answers.count(200)} of {PROBES} /healthz probes failed: {answers}")
    check(scrape is not None and scrape[0] == 200, f"/metrics under attack: {scrape}")
    check(value_of(parse_samples(scrape[1]), "rsg_http_connections_open") <= 32, "more connections open than the limit")

    check(h.wait("sim", sim, 30) == 0, "rsg_sim failed")
    report = read_json(report_path)
    final = wait_for_stats(stats, lambda s: s["frames_received"] >= report["sent"], "the gateway to count every datagram")
    check(final["frames_published"] == report["valid"] == count, f"published {final['frames_published']} of {count}")

    answer = http_get(metrics, "/metrics")
    check(answer is not None and answer[0] == 200, "/metrics after the attack")
    lint = subprocess.run([promtool, "check", "metrics"], input=answer[1], capture_output=True, text=True, timeout=30)
    check(lint.returncode == 0, f"promtool check metrics (exit {lint.returncode}): {lint.stdout}{lint.stderr}")
    samples = parse_samples(answer[1])
    closed = {reason: value_of(samples, "rsg_http_connections_closed_total", reason=reason)
              for reason in ("per_client_limit", "total_limit", "header_timeout", "idle_timeout")}
    print(f"[{h.name}] closed by the limits: {closed}", flush=True)
    # Which of the per-client limit and the timeouts bite besides depends on the order the
    # attackers' connections arrive in; the per-client limit alone: MetricsServer.*.
    check(closed["total_limit"] > 0, f"the connection limit never bit: {closed}")
    log = (h.dir / "gateway.err").read_text()
    for reason, count in closed.items():
        lines = log.count(f"closed so far by {reason}")
        check(lines == (1 if count > 0 else 0), f"{reason} logged {lines} times in {ATTACK_S} s (once a minute at most)")

    time.sleep(1.0)
    rss_after = rss_kb(gateway.pid)
    print(f"[{h.name}] gateway RSS before {rss_before} kB, after {rss_after} kB", flush=True)
    check(rss_after - rss_before < 8 * 1024, f"RSS grew from {rss_before} to {rss_after} kB")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("metrics_attack", body))
