"""A multi-host test bed on one Linux machine: network namespaces as hosts.

    robot 198.18.0.1 ─┐
    gw    198.18.0.2 ─┤  veth pairs, MTU 1500, to one bridge that lives in a namespace of its own
    ops1  198.18.0.3 ─┤  (198.18.0.0/15 is the benchmarking range: nothing real answers there)
    ops2  198.18.0.4 ─┘

Every run names its namespaces `rsgnet<pid>-<host>`, so parallel runs never collide, and removes
them at exit, on failure and on SIGTERM/SIGINT. A run killed with SIGKILL cannot clean up: the next
run sweeps namespaces whose pid is no longer alive (killing what still runs in them first).

Needs root (CAP_NET_ADMIN) and iproute2; nftables for the packet counters. Fails with a clear
message, never skips, when they are missing.
"""

import atexit
import hashlib
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from harness import TestFailure, check  # noqa: E402,F401

HOSTS = {"robot": "198.18.0.1", "gw": "198.18.0.2", "ops1": "198.18.0.3", "ops2": "198.18.0.4"}
PREFIX = 24
MTU = 1500
NAME_PATTERN = re.compile(r"^rsgnet(\d+)-")


DISCOVERY_SERVER_PROFILE = (Path(__file__).resolve().parents[2] / "xml_profiles" / "discovery_server" /
                            "rsg_discovery_server.xml")


def discovery_server_argv(port):
    """`fastdds discovery` on gw as docs/deploying.md deploys it: server id 0, with rsg's server profile."""
    return ["fastdds", "discovery", "-i", "0", "-l", HOSTS["gw"], "-p", str(port), "-x", str(DISCOVERY_SERVER_PROFILE)]


def sh(*argv, check_status=True):
    """Runs a command; on failure raises TestFailure with its stderr."""
    result = subprocess.run([str(a) for a in argv], capture_output=True, text=True)
    if check_status and result.returncode != 0:
        raise TestFailure(f"`{' '.join(map(str, argv))}` failed ({result.returncode}): {result.stderr.strip()}")
    return result.stdout


def namespaces():
    return [line.split()[0] for line in sh("ip", "netns", "list").splitlines() if line.strip()]


def remove_namespace(name):
    for pid in sh("ip", "netns", "pids", name, check_status=False).split():
        try:
            os.kill(int(pid), signal.SIGKILL)
        except ProcessLookupError:
            pass
    sh("ip", "netns", "del", name, check_status=False)


def sweep_stale():
    """Removes the namespaces of runs whose process is gone (killed before they could clean up)."""
    for name in namespaces():
        match = NAME_PATTERN.match(name)
        if not match:
            continue
        try:
            os.kill(int(match.group(1)), 0)
        except ProcessLookupError:
            remove_namespace(name)
        except PermissionError:
            pass  # alive, someone else's


def require_tools(*tools):
    missing = [tool for tool in tools if shutil.which(tool) is None]
    if missing:
        raise TestFailure(f"this test needs {', '.join(missing)} (Debian packages iproute2, nftables, ethtool; "
                          f"`make deps` installs them)")


class NetBed:
    """The four hosts and the bridge of one run. Use as a context manager.

    `off_sender` names hosts whose outgoing traffic the bridge takes in on a kernel thread of its
    own (the bridge port's veth in NAPI mode, GRO on, threaded NAPI; needs ethtool). By default a
    veth delivers what a process sends inside that process's system call: the bridge, the
    receiving host's IP stack and the receiver's wake-up are all charged to the sender, work that a
    NIC leaves to the receiving machine. With the host listed, the sender pays for its own send
    only, and the rest runs on `napi/b-<host>-…`."""

    def __init__(self, off_sender=()):
        self.off_sender = tuple(off_sender)
        self.run_id = f"rsgnet{os.getpid()}"
        self.bridge = f"{self.run_id}-br"
        self.made = []
        self.children = []

    def ns(self, host):
        return f"{self.run_id}-{host}"

    def __enter__(self):
        if os.geteuid() != 0:
            raise TestFailure("the network test bed needs root (network namespaces, veth, nftables): "
                              "run as root, as CI does")
        require_tools("ip", "nft", "tc", *(("ethtool",) if self.off_sender else ()))
        sweep_stale()
        atexit.register(self.close)
        for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
            signal.signal(sig, lambda number, frame: sys.exit(128 + number))
        try:
            self._build()
        except TestFailure as failure:
            raise TestFailure(f"cannot build the network namespaces: {failure}")
        return self

    def __exit__(self, *exc):
        self.close()

    def _add_namespace(self, name):
        sh("ip", "netns", "add", name)
        self.made.append(name)
        sh("ip", "-n", name, "link", "set", "lo", "up")

    def _build(self):
        self._add_namespace(self.bridge)
        sh("ip", "-n", self.bridge, "link", "add", "br0", "type", "bridge")
        sh("ip", "-n", self.bridge, "link", "set", "br0", "up")
        for host, address in HOSTS.items():
            name = self.ns(host)
            self._add_namespace(name)
            # Made inside the bridge's namespace: the names only have to be unique there.
            sh("ip", "-n", self.bridge, "link", "add", f"b-{host}", "mtu", MTU, "type", "veth", "peer", "name",
               "eth0", "mtu", MTU, "netns", name)
            sh("ip", "-n", self.bridge, "link", "set", f"b-{host}", "master", "br0", "up")
            sh("ip", "-n", name, "addr", "add", f"{address}/{PREFIX}", "dev", "eth0")
            sh("ip", "-n", name, "link", "set", "eth0", "up")
            # DDS discovery's multicast group goes out of eth0 (no default route in here).
            sh("ip", "-n", name, "route", "add", "224.0.0.0/4", "dev", "eth0")
            # rsg's participants ask for 4 MiB socket buffers; the kernel caps them at rmem_max.
            for key in ("net.core.rmem_max", "net.core.wmem_max"):
                sh("ip", "netns", "exec", name, "sysctl", "-qw", f"{key}=8388608")
        for host in self.off_sender:
            # NAPI on a veth needs GRO and both ends up; `threaded` then moves its poll loop, and the
            # forwarding and delivery it runs, from the sender's softirq to a kernel thread. A veth
            # hands a packet to its peer's NAPI only if the sending end has no TSO (or the peer
            # forwards UDP GRO); TSO means nothing to rsg's UDP, so it goes.
            port = f"b-{host}"
            try:
                sh("ip", "netns", "exec", self.ns(host), "ethtool", "-K", "eth0", "tso", "off")
                sh("ip", "netns", "exec", self.bridge, "ethtool", "-K", port, "gro", "on")
                sh("ip", "netns", "exec", self.bridge, "sh", "-c", f"echo 1 > /sys/class/net/{port}/threaded")
            except TestFailure as failure:
                raise TestFailure(f"{host}'s traffic cannot be taken in on a kernel thread here (veth NAPI, "
                                  f"threaded; Linux 5.12 or later): {failure} (the scale bench runs without "
                                  f"it with RSG_BENCH_SCALE_SENDER_PAYS=1)")

    def close(self):
        for _, process in self.children:
            if process.poll() is None:
                process.kill()
                process.wait()
        for name in reversed(self.made):
            remove_namespace(name)
        self.made.clear()

    # ----- processes --------------------------------------------------------------------------------

    def start(self, host, label, argv, directory, stdout=None):
        """Starts argv in `host`'s namespace; stdout/stderr into files of `directory` unless given."""
        out = stdout if stdout is not None else open(Path(directory) / f"{label}.out", "wb")
        err = open(Path(directory) / f"{label}.err", "wb")
        print(f"[{host}] start {label}: {' '.join(map(str, argv))}", flush=True)
        process = subprocess.Popen(["ip", "netns", "exec", self.ns(host), *map(str, argv)], stdout=out, stderr=err)
        self.children.append((label, process))
        return process

    def exec(self, host, *argv, check_status=True):
        return sh("ip", "netns", "exec", self.ns(host), *argv, check_status=check_status)

    # ----- links ------------------------------------------------------------------------------------

    def link(self, host, up):
        """The host's cable: its port on the bridge goes down or up."""
        sh("ip", "-n", self.bridge, "link", "set", f"b-{host}", "up" if up else "down")

    def pin_neighbours(self, host):
        """Static ARP on `host` for every other host (`nud permanent`, as a plant network may
        configure). Without it, `host` losing its carrier flushes its ARP cache; what it sends while
        the cable is out leaves INCOMPLETE entries, and after the cable is back its first packet to
        a peer waits for the entry's next ARP retransmission (up to net.ipv4.neigh.eth0.retrans_time_ms,
        1 s by default; 40-81 ms measured here): time in which nothing of `host` reaches the peer."""
        for peer, address in HOSTS.items():
            if peer != host:
                mac = self.exec(peer, "cat", "/sys/class/net/eth0/address").strip()
                sh("ip", "-n", self.ns(host), "neigh", "replace", address, "lladdr", mac, "dev", "eth0", "nud",
                   "permanent")

    def cap_bandwidth(self, host, rate):
        """A token-bucket cap on traffic towards `host` (the bridge port's egress), e.g. '8mbit'."""
        sh("tc", "-n", self.bridge, "qdisc", "add", "dev", f"b-{host}", "root", "tbf", "rate", rate, "burst",
           "32kb", "latency", "50ms")

    def tc_drops(self, host):
        stats = sh("tc", "-s", "-n", self.bridge, "qdisc", "show", "dev", f"b-{host}")
        match = re.search(r"dropped (\d+)", stats)
        return int(match.group(1)) if match else 0

    # ----- nftables counters ------------------------------------------------------------------------

    def counters(self, host, rules):
        """Named counters in `host`'s namespace: `rules` maps a name to (hook, nft match expression);
        every packet matching the expression on that hook counts. Returns a function giving
        {name: (packets, bytes)}, with `.reset()` to start again from zero."""
        lines = ["table inet rsg_count {"]
        for name in rules:
            lines.append(f"  counter c_{name} {{ }}")  # prefixed: a bare name may be an nft keyword
        for hook in sorted({hook for hook, _ in rules.values()}):
            lines.append(f"  chain {hook} {{ type filter hook {hook} priority 0; policy accept;")
            for name, (rule_hook, match) in rules.items():
                if rule_hook == hook:
                    lines.append(f"    {match} counter name c_{name}")
            lines.append("  }")
        lines.append("}")
        self.nft(host, "\n".join(lines))

        def read(reset=False):
            text = self.exec(host, "nft", "reset" if reset else "list", "counters", "table", "inet", "rsg_count")
            found = {}
            for name, packets, size in re.findall(r"counter c_(\w+) \{\s*packets (\d+) bytes (\d+)", text):
                found[name] = (int(packets), int(size))
            return found

        read.reset = lambda: read(reset=True)
        return read

    def nft(self, host, ruleset):
        process = subprocess.run(["ip", "netns", "exec", self.ns(host), "nft", "-f", "-"], input=ruleset,
                                 capture_output=True, text=True)
        if process.returncode != 0:
            raise TestFailure(f"nft in {host} refused:\n{ruleset}\n{process.stderr.strip()}")


class LineDigests(threading.Thread):
    """Reads a stream of JSON lines (a reader's stdout, the simulator's record through a FIFO) and
    keeps, per line, its arrival time and a digest of its bytes: 60 s of full frames are 220 MB of
    JSON per stream, too much to keep, but comparing digests is comparing the lines exactly."""

    def __init__(self, stream=None, path=None):
        super().__init__(daemon=True)
        self.stream, self.path = stream, path
        self.digests = []
        self.times = []
        self.groups = []  # each line's group_select

    def run(self):
        stream = self.stream if self.stream is not None else open(self.path, "rb")
        for line in stream:
            if not line.endswith(b"\n"):
                break
            self.times.append(time.monotonic())
            self.digests.append(hashlib.blake2b(line, digest_size=12).digest())
            match = re.search(rb'"group_select":(\d+)', line)
            self.groups.append(int(match.group(1)) if match else 0)
        stream.close()


def missing_runs(sent, received):
    """The runs of `sent` (lists of digests) missing from `received`, which must be a subsequence
    of it: returns [(first index, last index)], or None if `received` is not a subsequence."""
    runs, at = [], 0
    for index, digest in enumerate(sent):
        if at < len(received) and received[at] == digest:
            at += 1
        elif runs and runs[-1][1] == index - 1:
            runs[-1][1] = index
        else:
            runs.append([index, index])
    return [tuple(run) for run in runs] if at == len(received) else None
