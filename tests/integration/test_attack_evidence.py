"""The flight recorder's evidence, against an attacker on the network and a local user (issue 51):

- A real incident (the robot streams, then falls silent: a link_down dump), then forged link flaps
  from the allowed address, one a --pcap-min-interval apart, at --pcap-max-files 5
  --pcap-min-interval 1: the incident's dump is never rotated out (every dump is younger than the
  protected hour, so once the folder is full further dumps are not written, counted no_room).
  The control that shows the attack is real: more flaps passed --pcap-min-interval than the folder
  holds (each would have rotated out the oldest file). Before: the incident's dump was gone after 7.
- 100 files named like rsg's dumps and dated 2100, planted in --pcap-dir by another user (nobody):
  never counted, never deleted, and no real dump is deleted because of them. Before: each real
  dump was deleted at the next one.
- The link flaps' log: the first "link down" line at once, then counts, not a line per flap.
  Before: two lines per flap. The same for 3.5 s of datagrams from outside allow-from and of
  invalid frames from the allowed address: one line each. Before: a line a second each.
- A --pcap-dir others can write (mode 1777, a shared folder where symlinks could be planted under
  the next dump's name): the gateway refuses to start, exit 2, naming the folder; the control,
  the same folder made the gateway's own (0755), starts. (A symlink under the dump's name is never
  written through: DumpWriterTest.ADumpIsNeverWrittenThroughASymlinkUnderItsName.)
"""

import os
import socket
import sys
import time

from attack_support import JunkFlood, checked_scrape, valid_frame
from harness import check, free_udp_port, main, wait_for, wait_for_stats
from metrics_support import free_tcp_port, http_get, value_of

MAX_FILES = 5
FLAPS = 9
PLANTED = 100
NOBODY = 65534


class Stream:
    """Valid frames from 127.0.0.1 whose packet numbers follow on and whose time follows this host's
    clock: the robot's stream, or frames forged to continue it (docs/security.md: they are
    indistinguishable)."""

    def __init__(self, port):
        self.port, self.number, self.start = port, 0, time.monotonic()
        self.socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)

    def send(self, count, rate):
        begin = time.monotonic()
        for i in range(count):
            delay = begin + i / rate - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            time_ms = int((time.monotonic() - self.start) * 1000)
            self.socket.sendto(valid_frame(self.number, time_ms), ("127.0.0.1", self.port))
            self.number += 1


def dumps_of(samples):
    return {result: value_of(samples, "rsg_flight_recorder_dumps_total", result=result)
            for result in ("written", "throttled", "refused", "failed", "no_room")}


def body(h):
    check(os.geteuid() == 0, "planting another user's files needs root (chown): run this test as root")
    folder = h.dir / "dumps"
    folder.mkdir(mode=0o755)
    os.chmod(folder, 0o755)
    planted = []
    for i in range(PLANTED):
        path = folder / f"rsg_flight_21000101T0000{i % 60:02d}.000Z_{i}_link_down.pcap"
        path.write_bytes(b"\0" * 1000)
        stamp = 4102444800 + i  # 2100-01-01
        os.utime(path, (stamp, stamp))
        os.chown(path, NOBODY, NOBODY)
        planted.append(path)

    # A shared folder is refused, and the gateway's own is the control.
    shared = h.dir / "shared"
    shared.mkdir()
    os.chmod(shared, 0o1777)
    port, metrics = free_udp_port(), free_tcp_port()
    flags = ["--listen", f"127.0.0.1:{port}", "--allow-from", "127.0.0.1", "--expected-rate", "100",
             "--pcap-ring", "1", "--pcap-max-files", str(MAX_FILES), "--pcap-min-interval", "1",
             "--metrics", f"127.0.0.1:{metrics}"]
    refused, _ = h.gateway("refused", *flags, "--pcap-dir", str(shared))
    check(h.wait("refused", refused, 30) == 2, "the gateway started on a folder others can write")
    err = (h.dir / "refused.err").read_text(errors="replace")
    check(f"--pcap-dir: '{shared}'" in err and "is writable by others than its owner" in err,
          f"the refusal does not name the folder: {err}")

    gateway, stats = h.gateway("gateway", *flags, "--pcap-dir", str(folder))
    wait_for(lambda: gateway.poll() is not None or http_get(metrics, "/metrics"), "the gateway's /metrics")
    check(gateway.poll() is None, f"the gateway exited {gateway.poll()} on its own folder")

    # The real incident: a second of the robot's stream, then silence (the link is down 100 ms later).
    stream = Stream(port)
    stream.send(200, 200)
    samples = wait_for(lambda: (lambda s: s if dumps_of(s)["written"] >= 1 else None)(checked_scrape(h, metrics, "incident")),
                       "the incident's dump")
    ours = lambda: sorted(p for p in folder.iterdir() if p.name.startswith("rsg_flight_") and p not in planted)
    incident = ours()
    check(len(incident) == 1, f"the incident left {len(incident)} dumps")
    incident = incident[0]

    # Forged flaps: one valid frame (link up), then silence (link down), a little over
    # --pcap-min-interval apart, so that none is throttled.
    for _ in range(FLAPS):
        time.sleep(1.2)
        stream.send(2, 100)
    samples = wait_for(lambda: (lambda s: s if sum(dumps_of(s).values()) >= 1 + FLAPS else None)(
        checked_scrape(h, metrics, "flaps")), "every flap's dump request to be counted")
    dumps = dumps_of(samples)
    print(f"flaps: {FLAPS} forged link downs: {dumps}")
    # The control: more dumps passed --pcap-min-interval than the folder holds.
    check(dumps["written"] + dumps["no_room"] >= MAX_FILES + 2, f"the flaps did not press on the folder: {dumps}")
    check(incident.exists(), "the incident's dump was rotated out by forged flaps")
    check(len(ours()) <= MAX_FILES, f"{len(ours())} of rsg's files, more than --pcap-max-files {MAX_FILES}")
    check(dumps["no_room"] >= 1 and value_of(samples, "rsg_flight_recorder_files_deleted_total") == 0,
          f"a file was deleted or no dump was held back: {dumps}")
    gone = [p.name for p in planted if not p.exists()]
    check(not gone, f"{len(gone)} planted files of another user deleted: {gone[:3]}")

    # The log: not a line per flap.
    text = (h.dir / "gateway.err").read_text(errors="replace")
    down_lines = sum(1 for line in text.splitlines() if "link down (" in line)
    check(down_lines <= 2, f"{down_lines} 'link down' lines for {1 + FLAPS} link downs")
    # Steady bad input for 3.5 s (over three status periods, each of which logged a line before):
    # datagrams from outside allow-from, and invalid ones from the allowed address (a misconfigured
    # robot). One line each, then a count a minute.
    floods = [JunkFlood(port, source="127.0.0.2", rate=500), JunkFlood(port, source="127.0.0.1", rate=500)]
    for flood in floods:
        flood.start()
    time.sleep(3.5)
    for flood in floods:
        flood.stop()
    wait_for_stats(stats, lambda s: s["rejected_source"] >= 1000 and sum(s["invalid"].values()) >= 1000,
                   "the bad input to be counted")
    time.sleep(1.5)  # two more status periods
    text = (h.dir / "gateway.err").read_text(errors="replace")
    foreign, invalid = text.count("from outside --allow-from"), text.count("rejected invalid frames")
    check(foreign == 1 and invalid == 1, f"{foreign} lines for datagrams from outside allow-from, {invalid} for "
                                         "invalid frames, over 3.5 s of each")
    stream.socket.close()
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("attack_evidence", body))
