"""rsg_gateway under a Type=notify supervisor, played by the test: NOTIFY_SOCKET names a Unix datagram
socket the test reads, as systemd's would be. READY=1 comes once the gateway is up (its UDP port is
bound, its stats file written, so its DDS writers exist), STATUS= lines follow each status period,
WATCHDOG=1 keeps arriving while the gateway runs (WATCHDOG_USEC=1 s: at least every half second),
stops while the gateway is frozen with SIGSTOP, resumes on SIGCONT, and stops again while only the
main loop is stuck and every other thread runs (Fast DDS's, the metrics server's, which then answers
/healthz 503 "stale"): no timer thread pings for a stuck gateway. STOPPING=1 comes on SIGTERM.

A disk that hangs (a full disk, a hung NFS mount: here the stats file's next write opens a FIFO
that no one reads) does not stop the main loop: the stats file has a writer thread of its own, and
WATCHDOG=1 keeps arriving. The main loop alone is stuck the way a debugger stops one thread:
ptrace (PTRACE_SEIZE + PTRACE_INTERRUPT) on the thread that runs it, the process's main thread."""

import os
import signal
import socket
import sys
import threading
import time

from pathlib import Path

from harness import check, free_udp_port, main, port_is_free, read_json, wait_for
from metrics_support import free_tcp_port, http_get
from thread_freeze import freeze_thread, thaw_thread

WATCHDOG_USEC = 1_000_000


class NotifySocket(threading.Thread):
    """Collects (arrival time, message) of every datagram sent to a Unix socket at `path`."""

    def __init__(self, path):
        super().__init__(daemon=True)
        self.socket = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self.socket.bind(str(path))
        self.socket.settimeout(0.2)
        self.messages, self.stopping = [], False

    def run(self):
        while not self.stopping:
            try:
                data = self.socket.recv(4096)
            except socket.timeout:
                continue
            self.messages.append((time.monotonic(), data.decode()))

    def since(self, start, prefix):
        return [message for when, message in list(self.messages) if when >= start and message.startswith(prefix)]

    def stop(self):
        self.stopping = True
        self.join()
        self.socket.close()


def body(h):
    notify = NotifySocket(h.dir / "notify")
    notify.start()
    port = free_udp_port()
    stats = h.dir / "gateway.stats.json"
    seen_at_ready = {}

    def ready():
        if not notify.since(0, "READY=1"):
            return False
        if not seen_at_ready:  # what existed when READY arrived
            seen_at_ready.update(stats=read_json(stats), bound=not port_is_free(port))
        return True

    os.environ.update(NOTIFY_SOCKET=str(h.dir / "notify"), WATCHDOG_USEC=str(WATCHDOG_USEC))
    try:
        metrics = free_tcp_port()
        gateway, _ = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--metrics", f"127.0.0.1:{metrics}")
    finally:
        del os.environ["NOTIFY_SOCKET"], os.environ["WATCHDOG_USEC"]
    wait_for(ready, "READY=1 from the gateway", interval_s=0.01)
    check(seen_at_ready["stats"] is not None, "READY=1 came before the gateway had written its stats file")
    check(seen_at_ready["bound"], "READY=1 came before the gateway's UDP port was bound")
    check(len(notify.since(0, "READY=1")) == 1, "READY=1 sent more than once")
    ready_message = notify.since(0, "READY=1")[0]
    check("\nSTATUS=link down, 0 readers" in ready_message, f"READY without its status line: {ready_message!r}")

    start = time.monotonic()
    wait_for(lambda: len(notify.since(start, "WATCHDOG=1")) >= 4, "WATCHDOG=1 to keep arriving")
    wait_for(lambda: notify.since(start, "STATUS="), "a STATUS= line each status period")

    gateway.send_signal(signal.SIGSTOP)
    stopped = time.monotonic() + 0.2  # a ping already on its way may still arrive
    time.sleep(3 * WATCHDOG_USEC / 1e6)
    frozen = notify.since(stopped, "WATCHDOG=1")
    gateway.send_signal(signal.SIGCONT)
    check(not frozen, f"{len(frozen)} WATCHDOG=1 while the gateway was stopped: pinged from outside the main loop")
    resumed = time.monotonic()
    wait_for(lambda: notify.since(resumed, "WATCHDOG=1"), "WATCHDOG=1 again after SIGCONT")

    # A hung disk: the stats file's next write blocks on a FIFO; the main loop goes on.
    partial = Path(str(stats) + ".partial")

    def plant_fifo():
        try:
            os.mkfifo(partial)
            return True
        except FileExistsError:  # the gateway is writing it right now
            return False
    wait_for(plant_fifo, "a FIFO in place of the stats file's next write")
    time.sleep(1.5)  # the writer thread reaches its next write (1 s) and blocks in open()
    blocked = time.monotonic()
    time.sleep(3 * WATCHDOG_USEC / 1e6)
    pings_while_disk_hangs = notify.since(blocked, "WATCHDOG=1")
    reader = os.open(partial, os.O_RDONLY | os.O_NONBLOCK)  # unblocks the writer thread
    try:
        check(len(pings_while_disk_hangs) >= 4,
              f"{len(pings_while_disk_hangs)} WATCHDOG=1 while the stats file's disk hung: the main loop waited on it")
        written = []  # read until the writer has written and closed (closing earlier would SIGPIPE it)

        def drained():
            try:
                chunk = os.read(reader, 65536)
            except BlockingIOError:
                return False
            written.append(chunk)
            return len(written) > 1 and not chunk and any(written)
        wait_for(drained, "the writer thread to write its stats into the FIFO")
    finally:
        os.close(reader)
    wait_for(lambda: not partial.exists() or not partial.is_fifo(), "the FIFO to be renamed away")

    # Only the main loop stuck.
    freeze_thread(gateway.pid)
    try:
        stuck = time.monotonic() + 0.2  # a ping already on its way may still arrive
        time.sleep(3 * WATCHDOG_USEC / 1e6)
        pings_while_stuck = notify.since(stuck, "WATCHDOG=1")
        health = http_get(metrics, "/healthz")
    finally:
        thaw_thread(gateway.pid)
    check(not pings_while_stuck,
          f"{len(pings_while_stuck)} WATCHDOG=1 while the main loop was stuck: pinged from another thread")
    check(health is not None and health[0] == 503 and health[1].startswith("stale"),
          f"/healthz while the loop was stuck: {health}")
    unstuck = time.monotonic()
    wait_for(lambda: notify.since(unstuck, "WATCHDOG=1"), "WATCHDOG=1 again once the loop runs")

    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    check(notify.since(0, "STOPPING=1"), "no STOPPING=1 on SIGTERM")
    notify.stop()


if __name__ == "__main__":
    sys.exit(main("systemd_notify", body))
