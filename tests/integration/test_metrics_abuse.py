"""Bad clients on the metrics port never stall ingress: while rsg_sim streams at 1 kHz, 200 idle
connections, clients that never finish their request, huge request headers and requests for unknown
paths hit --metrics, and the gateway publishes every frame sent (frames_published == valid frames
sent, nothing lost), stays up, and answers /metrics again once the bad clients are gone."""

import re
import socket
import sys
import threading
import time

from harness import check, main, read_json, wait_for, wait_for_stats
from metrics_support import http_get, start_gateway

COUNT = 5000  # 5 s at 1 kHz
RATE = "1000"
IDLE = 200


class Abuse(threading.Thread):
    """Runs `attack(port)` over and over until stopped; counts what it did."""

    def __init__(self, port, attack):
        super().__init__(daemon=True)
        self.port, self.attack, self.stopping, self.rounds, self.errors = port, attack, False, 0, 0

    def run(self):
        while not self.stopping:
            try:
                self.attack(self.port)
            except OSError:
                self.errors += 1
            self.rounds += 1

    def stop(self):
        self.stopping = True
        self.join(timeout=15)


def connect(port):
    return socket.create_connection(("127.0.0.1", port), timeout=5)


def huge_headers(port):
    with connect(port) as client:
        client.sendall(b"GET /metrics HTTP/1.1\r\nHost: x\r\n" + b"X-Padding: " + b"a" * 100_000 + b"\r\n\r\n")
        client.recv(4096)


def slow_client(port):
    with connect(port) as client:
        client.sendall(b"GET /metrics HTTP/1.1\r\n")
        for _ in range(3):  # a byte a second, never the end of the request
            time.sleep(1)
            client.sendall(b"X")


def unknown_paths(port):
    for path in ("/", "/admin", "/metrics/../etc/passwd", "/" + "x" * 4000):
        answer = http_get(port, path)
        if answer is not None and answer[0] != 404:
            raise AssertionError(f"{path[:40]} answered {answer[0]}")


def body(h):
    gateway, stats, udp, metrics = start_gateway(h, "gateway", rate=RATE)
    idle = []
    for _ in range(IDLE):
        try:
            idle.append(connect(metrics))  # connected and silent: past the cap the server closes them
        except OSError:
            pass
    attackers = [Abuse(metrics, attack) for attack in (huge_headers, slow_client, slow_client, unknown_paths)]
    for attacker in attackers:
        attacker.start()

    report_path = h.dir / "sim.report.json"
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{udp}", "--rate", RATE, "--count", str(COUNT),
                           "--report", str(report_path)], timeout_s=40)
    check(status == 0, f"rsg_sim exited {status}")
    for attacker in attackers:
        attacker.stop()
    for client in idle:
        client.close()
    check(all(a.rounds > 0 for a in attackers), "an attacker never ran")
    report = read_json(report_path)
    final = wait_for_stats(stats, lambda s: s["frames_received"] >= report["sent"], "the gateway to count every datagram")
    check(gateway.poll() is None, f"the gateway exited {gateway.poll()} under the bad clients")
    check(final["frames_published"] == report["valid"] == COUNT and final["lost"] == 0,
          f"published {final['frames_published']} of {report['valid']} sent, lost {final['lost']}")
    def served():
        answer = http_get(metrics, "/metrics")
        # Every series carries the gateway label (the host name unless --name says otherwise).
        return answer and answer[0] == 200 and re.search(rf"\nrsg_frames_published_total\{{gateway=\"[^\"]*\"\}} {COUNT}\n", answer[1])
    wait_for(served, f"/metrics to answer, with {COUNT} frames published, once the bad clients left")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("metrics_abuse", body))
