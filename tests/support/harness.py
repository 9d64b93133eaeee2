"""Shared plumbing of the multi-process tests: binaries, ports, DDS domains, child processes.

Every test gets its own DDS domain (tests/support/test_domain.py: held by a lock while the test runs,
so tests run side by side by `ctest -j` never share one) and its own UDP ports, so tests never see
each other's traffic; every child process is killed when the test ends, passed or not; every wait is
bounded.
"""

import argparse
import json
import os
import shutil
import signal
import socket
import struct
import subprocess
import tempfile
import threading
import time
from pathlib import Path

from test_domain import acquire_domain, others_running, test_domain, test_port  # noqa: E402,F401  (re-exported)

# Generous on purpose: a 2-core machine shared with builds makes discovery and start-up slow.
DEFAULT_WAIT_S = 20.0


class TestFailure(Exception):
    pass


def thread_dump(pid):
    """What each thread of a process that does not exit is doing: its name (rsg names its threads),
    state and kernel wait channel from /proc, and with gdb installed every thread's stack."""
    lines = []
    for task in sorted(Path(f"/proc/{pid}/task").glob("*"), key=lambda p: int(p.name)):
        try:
            name = (task / "comm").read_text().strip()
            state = next(l for l in (task / "status").read_text().splitlines() if l.startswith("State:"))
            wchan = (task / "wchan").read_text().strip()
        except (OSError, StopIteration):
            continue
        lines.append(f"  {task.name} {name}: {state.split(None, 1)[1]}, waiting in {wchan or '-'}")
    if shutil.which("gdb"):
        dump = subprocess.run(["gdb", "-p", str(pid), "-batch", "-nx", "-ex", "thread apply all bt 30"],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=120)
        lines += [l for l in dump.stdout.splitlines() if l.startswith(("Thread ", "#"))]
    return "\n".join(lines)


def check(condition, message):
    if not condition:
        raise TestFailure(message)


def wait_for(predicate, what, timeout_s=DEFAULT_WAIT_S, interval_s=0.05):
    """Polls `predicate` until it returns something truthy; fails naming `what` on timeout."""
    deadline = time.monotonic() + timeout_s
    while True:
        result = predicate()
        if result:
            return result
        if time.monotonic() > deadline:
            raise TestFailure(f"timed out after {timeout_s:.0f} s waiting for {what}")
        time.sleep(interval_s)


def wait_reader_matched(h, label, tool, writers=1):
    """Waits until the tool started as `label` (rsg_echo, rsg_record) says on stderr that its reader
    matched `writers` writer(s). A gateway's `state_readers` is the writer's side of discovery; the
    reader may learn of the writer later, and a volatile reader misses what is sent in between."""
    line = f"{tool}: matched {writers} writer{'' if writers == 1 else 's'} of "
    err = h.dir / f"{label}.err"
    wait_for(lambda: err.exists() and line in err.read_text(errors="replace"), f"{label}'s reader to match")


def wait_matched(h, stats, labels, tool):
    """Both sides of discovery before the robot starts: the gateway's writer counts the readers of
    the tools started as `labels`, and each of those says its reader matched the writer."""
    wait_for_stats(stats, lambda s: s["state_readers"] >= len(labels), f"{len(labels)} reader(s) to match the gateway")
    for label in labels:
        wait_reader_matched(h, label, tool)


def realtime_prefix():
    """`chrt -f 20` when the kernel lets this process use SCHED_FIFO, else nothing: for a robot
    (rsg_sim) that must stream on time while the tests beside it load the cores."""
    probe = subprocess.run(["chrt", "-f", "20", "true"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return ["chrt", "-f", "20"] if probe.returncode == 0 else []


def free_udp_port():
    """A port of this test's own block, no one bound to it right now (test_domain.test_port: not the
    kernel's pick for port 0, which another process's port-0 socket may take before ours binds it)."""
    return test_port()


def free_tcp_port():
    """The same for a TCP server (a metrics or view port): the block's ports are free for both."""
    return test_port()


def port_is_free(port):
    """Whether UDP `port` on 127.0.0.1 can be bound right now (no one holds it)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        try:
            probe.bind(("127.0.0.1", port))
            return True
        except OSError:
            return False


def read_json(path):
    try:
        return json.loads(Path(path).read_text())
    except (FileNotFoundError, json.JSONDecodeError):
        return None


def read_json_lines(path):
    """The complete lines of a file another process may still be writing."""
    text = Path(path).read_text() if Path(path).exists() else ""
    complete = text.split("\n")[:-1]  # the part after the last newline may be half written
    return [json.loads(line) for line in complete if line.strip()]


def paced_count(times_ms, period_ms):
    """How many of the frames stamped `times_ms` (the robot's `time`, in order) an output paced by
    the robot's time at one per `period_ms` takes: one per period-long window, from the first frame,
    that holds a frame. The robot's clock runs on through a pause (rsg_sim's --pause-after, a real
    robot's gap) with no frame due then: counting on frames sent times the period would expect too
    many. After a gap of a period or more the pacing starts again from the
    next frame, which may take one window more or less."""
    return len({(t - times_ms[0]) // period_ms for t in times_ms}) if times_ms else 0


class Harness:
    """Owns the children and the scratch directory of one test."""

    def __init__(self, name):
        parser = argparse.ArgumentParser()
        parser.add_argument("--bin", required=True, help="directory of rsg_gateway, rsg_sim, rsg_echo")
        # The build tree keeps the tools in bin/ and every other executable in tests/bin/
        # (CONTRIBUTING.md, "Build tree"): ctest gives both; by hand --bin build/bin is enough.
        parser.add_argument("--test-bin", help="directory of the test helpers (default: tests/bin beside --bin)")
        self.args = parser.parse_args()
        self.bin = Path(self.args.bin)
        self.test_bin = Path(self.args.test_bin) if self.args.test_bin else self.bin.parent / "tests" / "bin"
        self.name = name
        self.dir = Path(tempfile.mkdtemp(prefix=f"rsg_{name}_"))
        self.domain = test_domain()
        self.children = []

    def binary(self, name):
        """The path of an executable of --bin, else of --test-bin (a directory of wrappers, as
        test-fastdds3's, holds both kinds in --bin); a test fails (never skips) when it is not built."""
        for directory in (self.bin, self.test_bin):
            if (directory / name).exists():
                return str(directory / name)
        raise TestFailure(f"{name} is in neither {self.bin} nor {self.test_bin}: cmake --build build --target {name}")

    def start(self, label, argv, stdin=None):
        """Starts a child with stdout and stderr in files of the scratch directory."""
        stdout = open(self.dir / f"{label}.out", "wb")
        stderr = open(self.dir / f"{label}.err", "wb")
        print(f"[{self.name}] start {label}: {' '.join(map(str, argv))}", flush=True)
        process = subprocess.Popen(argv, stdin=stdin, stdout=stdout, stderr=stderr)
        self.children.append((label, process))
        return process

    def run(self, label, argv, timeout_s=45.0):
        """Runs a child to completion; returns its exit status."""
        process = self.start(label, argv)
        try:
            return process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            raise TestFailure(f"{label} did not finish within {timeout_s:.0f} s")

    def wait(self, label, process, timeout_s=DEFAULT_WAIT_S):
        try:
            return process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            print(f"--- {label} (pid {process.pid}) still running after {timeout_s:.0f} s: its threads")
            print(thread_dump(process.pid))
            raise TestFailure(f"{label} did not exit within {timeout_s:.0f} s")

    def stop(self, label, process):
        """SIGTERM, as an operator would; the gateway must exit 0."""
        process.send_signal(signal.SIGTERM)
        return self.wait(label, process)

    def output(self, label):
        return self.dir / f"{label}.out"

    def secure_profiles(self):
        """A fresh test PKI, and a directory with rsg's profiles and the PKI's participant profiles
        (rsg_secure_gateway, _reader, _intruder, _commander), as docs/security.md tells operators to make."""
        source = Path(__file__).resolve().parents[2] / "xml_profiles"
        pki = self.dir / "pki"
        subprocess.run([source / "security/make_test_pki.sh", pki], check=True, stdout=subprocess.DEVNULL)
        profiles = self.dir / "profiles"
        profiles.mkdir()
        for file in [*sorted(source.glob("*.xml")), pki / "rsg_secure_profiles.xml"]:
            (profiles / file.name).write_bytes(file.read_bytes())
        return profiles

    def gateway(self, label, *flags):
        stats = self.dir / f"{label}.stats.json"
        argv = [self.binary("rsg_gateway"), "--domain", str(self.domain), "--stats-file", str(stats), *flags]
        return self.start(label, argv), stats

    def cleanup(self, keep_outputs):
        """Kills every child still running; removes the scratch directory unless the test failed."""
        for label, process in self.children:
            if process.poll() is None:
                process.kill()
                process.wait()
        clean_shared_memory()
        if not keep_outputs:
            shutil.rmtree(self.dir, ignore_errors=True)

    def dump_logs(self):
        """The end of every child's stderr; stdout (JSON samples) stays in the scratch directory."""
        print(f"(outputs are in {self.dir})")
        for label, _ in self.children:
            path = self.dir / f"{label}.err"
            if path.exists() and path.stat().st_size:
                lines = path.read_text(errors="replace").splitlines()
                print(f"--- {label}.err (last 20 lines)")
                print("\n".join(line[:300] for line in lines[-20:]))


def clean_shared_memory():
    """Removes the shared-memory files of Fast DDS processes that died (`fastdds shm clean`), only
    while no other test runs: it takes a port whose lock file is not locked yet for a dead one, and a
    participant of a test starting beside it can be between creating its port and locking it."""
    if not others_running():
        subprocess.run(["fastdds", "shm", "clean"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def main(name, body):
    """Runs `body(harness)`; exit 0 on success, 1 on failure (with the children's logs)."""
    harness = Harness(name)
    clean_shared_memory()
    passed = False
    try:
        body(harness)
        passed = True
        print(f"[{name}] passed")
        return 0
    except TestFailure as failure:
        print(f"[{name}] FAILED: {failure}")
        harness.dump_logs()
        return 1
    finally:
        harness.cleanup(keep_outputs=not passed)


def wait_for_stats(stats_path, predicate, what, timeout_s=DEFAULT_WAIT_S):
    """Waits until the gateway's --stats-file satisfies `predicate`; returns the stats."""
    return wait_for(lambda: (lambda s: s if s and predicate(s) else None)(read_json(stats_path)), what, timeout_s)


# Linux's socket option for arrival times in nanoseconds (asm-generic/socket.h); Python's socket
# module does not name it.
SO_TIMESTAMPNS = 35


def timed_receiver():
    """A UDP socket on 127.0.0.1 (any port) whose datagrams carry the kernel's arrival time, so that
    a test process scheduled late does not shorten a span it measures."""
    receiver = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    receiver.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 << 20)
    receiver.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
    receiver.bind(("127.0.0.1", 0))
    return receiver


def receive_timed(receiver, count, timeout_s=10.0, quiet_s=0.3):
    """`count` datagrams as (arrival time in s, bytes), then any that follow within `quiet_s` (a
    test checks there are none; None: return at once); fails when fewer than `count` arrive within
    `timeout_s`."""
    received = []
    deadline = time.monotonic() + timeout_s
    while True:
        if len(received) >= count and quiet_s is None:
            return received
        left = deadline - time.monotonic() if len(received) < count else quiet_s
        if left <= 0:
            raise TestFailure(f"received {len(received)} of {count} datagrams within {timeout_s:.0f} s")
        receiver.settimeout(left)
        try:
            received.append(_timed_datagram(receiver))
        except socket.timeout:
            if len(received) >= count:
                return received


def _timed_datagram(receiver):
    data, ancillary, _, _ = receiver.recvmsg(65536, socket.CMSG_SPACE(16))
    stamp = next((item for level, kind, item in ancillary if level == socket.SOL_SOCKET and kind == SO_TIMESTAMPNS),
                 None)
    check(stamp is not None, "a datagram without its kernel arrival time")
    seconds, nanoseconds = struct.unpack("qq", stamp[:16])
    return seconds + nanoseconds * 1e-9, data


class UdpRelay(threading.Thread):
    """Receives on `port`, records every datagram and its kernel arrival time (`times`, in s),
    forwards it to `forward_to` (when given)."""

    def __init__(self, port, forward_to=None):
        super().__init__(daemon=True)
        self.socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.socket.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 << 20)
        self.socket.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
        self.socket.bind(("127.0.0.1", port))
        self.socket.settimeout(0.2)
        self.forward_to = forward_to
        self.datagrams = []
        self.times = []
        self.stopping = False

    def run(self):
        while not self.stopping:
            try:
                arrival, datagram = _timed_datagram(self.socket)
            except socket.timeout:
                continue
            self.datagrams.append(datagram)
            self.times.append(arrival)
            if self.forward_to:
                self.socket.sendto(datagram, self.forward_to)

    def stop(self):
        self.stopping = True
        self.join()
        self.socket.close()
