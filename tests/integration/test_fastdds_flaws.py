"""No published Fast DDS flaw reaches the gateway (issue 46; docs/fastdds-versions.md, "Published
Fast DDS flaws, as tested").

Each flaw of tests/support/fastdds_flaws.py, sent as a made-up participant would, unicast to every
port of the domain and to its discovery multicast group, on loopback; the DATA_FRAG ones also from a
writer of robot_state the made-up participant announced, to every reader of the topic (unicast: no
user reader listens on the multicast port):

  1. the control: against rsg_fastdds_flaws_probe, a plain Fast DDS participant with a reader (none
     of rsg's defences), alone on a DDS domain of its own: what the flaw does to the Fast DDS this
     build links, measured and printed (a signal, a thread spinning, resident memory growing, no
     answer to a new participant within 1 s) or "no effect here". On Fast DDS 2.9 (Debian 12, the default
     build) the three crash rows must crash it, unicast and multicast, and on every Fast DDS the "held"
     row must add its megabytes to it: else the test no longer shows what it says;
  2. against rsg: a gateway fed at 1 kHz by rsg_sim, with rsg_echo, rsg_record and rsg_view reading
     it on its domain: after each attack the gateway still runs and publishes, the reader still gets
     samples, the three tools still run, the gateway's resident memory stays bounded (a "held" row adds
     less than HELD_LIMIT_KB); at the end a
     reader started after every attack matches and gets samples.

By hand: RSG_FLAWS_ONLY=control (or rsg) runs one half; RSG_FLAWS_ROWS=CVE-2025-62799,... some rows.
"""

import os
import signal
import sys
import time
from pathlib import Path

from harness import acquire_domain, check, free_tcp_port, free_udp_port, main, read_json, wait_for, wait_for_stats
from metrics_support import http_get, parse_samples
from dds_attacks import answers_new_participant, participant_announcement, udp_ports_of
from fastdds_flaws import FLAWS, attack

# How long the control watches the probe after an attack: every crash seen on 2.9.1 came within 1 s
# on a quiet machine; a crash row on 2.9, which must crash it, is watched longer, for a loaded one
# (a probe seen dying 1.5 s after the attack, its memory already going).
WATCH_S = 1.5
WATCH_CRASH_S = 6.0
# What the gateway's resident memory may grow by over every attack (the screen drops them: about
# 0.5 MB seen; Fast DDS without it grew by hundreds of MB/s), and the size at which the test stops
# at once.
GATEWAY_GROWTH_LIMIT_KB = 32 * 1024
RUNAWAY_KB = 1024 * 1024
CLOCK_TICKS = os.sysconf("SC_CLK_TCK")
# What the control calls an effect in a probe that did not crash (an idle one: no thread runnable
# more than a few % of the time, no growth): a thread that spins (runnable all the time, however
# little of a core a loaded machine gives it), memory growing, discovery not answering.
SPINNING_RUNNABLE = 50
GROWING_MB_S = 20
# A "held" row (memory kept for the made-up participant's lifetime, tests/support/fastdds_flaws.py):
# what it must add to the plain participant (the control: about 7 MB announced), and what it may add
# to the gateway (Fast DDS's data_limits, as rsg sets them, refuse the announcements).
HELD_SHOWN_KB = 4 * 1024
HELD_LIMIT_KB = 2 * 1024


def resident_kb(pid):
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    except OSError:
        pass
    return 0


def cpu_s(pid):
    """User + system CPU seconds of process `pid` so far (every thread)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / CLOCK_TICKS
    except OSError:
        return 0.0


def runnable_s(pid):
    """{thread id: seconds it has been on a core or waiting for one} of process `pid`
    (/proc/PID/task/*/schedstat): a thread that spins is runnable all the time, however little of a
    core a loaded machine gives it; one that waits, hardly ever."""
    threads = {}
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            on_cpu, waiting = (task / "schedstat").read_text().split()[:2]
            threads[task.name] = (int(on_cpu) + int(waiting)) / 1e9
        except (OSError, ValueError):
            pass
    return threads


def busiest_thread(before, after, elapsed_s):
    """The largest share of `elapsed_s` one thread was runnable, from two runnable_s() snapshots."""
    return max((after[tid] - before.get(tid, 0.0) for tid in after), default=0.0) / elapsed_s * 100


def signal_name(status):
    try:
        return signal.Signals(-status).name
    except ValueError:
        return f"signal {-status}"


class Control:
    """The probes, on a domain of their own, which nothing else of the test joins."""

    def __init__(self, h):
        self.h = h
        self.domain = acquire_domain()
        self.version = None
        self.effects = {}

    def run(self, flaw, way):
        h = self.h
        label = f"probe_{flaw.cve}_{flaw.target}_{way}"
        probe = h.start(label, [h.binary("rsg_fastdds_flaws_probe"), "--domain", str(self.domain), "--duration", "30"])
        out = h.output(label)
        wait_for(lambda: "reader created" in out.read_text() or probe.poll() is not None, f"{label} to start")
        check(probe.poll() is None, f"{label} exited {probe.poll()} at start: {out.read_text()}")
        self.version = next(line.split()[1] for line in out.read_text().splitlines() if line.startswith("fastdds "))
        ports = udp_ports_of(probe.pid)
        check(ports, f"{label} has no UDP port")
        time.sleep(0.2)  # its discovery threads past their start-up
        cpu0, runnable0, rss0, start = cpu_s(probe.pid), runnable_s(probe.pid), resident_kb(probe.pid), time.monotonic()
        attack(flaw, way, self.domain, ports)
        sent = time.monotonic()
        watch_s = WATCH_CRASH_S if flaw.kind == "crash" and self.version.startswith("2.9.") else WATCH_S
        while time.monotonic() - sent < watch_s and probe.poll() is None:
            time.sleep(0.02)
        if probe.poll() is not None:
            status = probe.returncode
            effect = (f"crashed ({signal_name(status)}) {time.monotonic() - sent:.2f} s after the attack"
                      if status < 0 else f"exited {status}")
            said = [line for line in (h.dir / f"{label}.err").read_text(errors="replace").splitlines() if line]
            if said:
                effect += f", its last words: {said[-1][:120]!r}"
            crashed = True
        else:
            elapsed = time.monotonic() - start
            cpu = (cpu_s(probe.pid) - cpu0) / elapsed * 100
            runnable = busiest_thread(runnable0, runnable_s(probe.pid), elapsed)
            grown_kb = resident_kb(probe.pid) - rss0
            growth = grown_kb / 1024 / elapsed
            answers = answers_new_participant(self.domain, free_udp_port(), ports, timeout_s=1.0)
            measured = (f"its busiest thread runnable {runnable:.0f} % of the time ({cpu:.0f} % of a core), resident memory "
                        f"{growth:+.0f} MB/s ({grown_kb / 1024:+.1f} MB), "
                        f"{'answers' if answers else 'no answer to'} a new participant")
            busy = (runnable >= SPINNING_RUNNABLE or growth >= GROWING_MB_S or not answers or
                    (flaw.kind == "held" and grown_kb >= HELD_SHOWN_KB))
            effect = f"{'still running, but' if busy else 'no effect here'}: {measured}"
            crashed = False
            if flaw.kind == "held":
                check(grown_kb >= HELD_SHOWN_KB,
                      f"the control: {flaw.name} sent {way} added {grown_kb} kB to a plain Fast DDS {self.version} "
                      f"participant (at least {HELD_SHOWN_KB} kB expected): the attack no longer shows what it says")
            probe.kill()
            probe.wait()
        if flaw.target == "user" and "matched 1" not in out.read_text():
            effect += " (its reader never matched the made-up writer)"
        print(f"[fastdds_flaws] control, Fast DDS {self.version}, {flaw.name} sent {way}: {effect}", flush=True)
        self.effects[(flaw, way)] = (crashed, effect)

    def check_shown(self):
        """On 2.9 (Debian 12's, the default build) the crash rows crash the plain participant: the
        flaws the test sends are the real ones."""
        if self.version is None or not self.version.startswith("2.9."):
            return
        for (flaw, way), (crashed, effect) in self.effects.items():
            check(flaw.kind != "crash" or crashed,
                  f"the control: {flaw.name} sent {way} did not crash a plain Fast DDS {self.version} participant "
                  f"({effect}): the attack is not the published flaw, or this Fast DDS has its fix")


class Gateway:
    """A gateway at 1 kHz, a reader, rsg_record and rsg_view, on the test's domain."""

    def __init__(self, h):
        self.h = h
        port, self.metrics_port = free_udp_port(), free_tcp_port()
        self.gateway, self.stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", "1000",
                                             "--metrics", f"127.0.0.1:{self.metrics_port}")
        wait_for_stats(self.stats, lambda s: True, "the gateway to start")
        domain = str(h.domain)
        self.tools = {
            "echo": h.start("echo", [h.binary("rsg_echo"), "--domain", domain, "--json", "--timeout", "20"]),
            "record": h.start("record", [h.binary("rsg_record"), "--domain", domain, "--out",
                                         str(h.dir / "attacked.mcap")]),
            "view": h.start("view", [h.binary("rsg_view"), "--domain", domain, "--listen",
                                     f"127.0.0.1:{free_tcp_port()}"]),
        }
        wait_for_stats(self.stats, lambda s: s["state_readers"] >= 3, "rsg_echo, rsg_record and rsg_view to match")
        h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--duration", "120"])
        self.wait_progress("before the attacks")
        self.rss0 = resident_kb(self.gateway.pid)
        self.tools_rss0 = {label: resident_kb(tool.pid) for label, tool in self.tools.items()}

    def samples(self):
        return self.h.output("echo").read_text(errors="replace").count("\n")

    def published(self):
        stats = read_json(self.stats)
        return stats["frames_published"] if stats else 0

    def alive(self, what):
        check(self.gateway.poll() is None, f"the gateway died {what} (exit {self.gateway.returncode}"
              f"{', ' + signal_name(self.gateway.returncode) if (self.gateway.returncode or 0) < 0 else ''})")
        for label, tool in self.tools.items():
            check(tool.poll() is None, f"rsg_{label} died {what} (exit {tool.returncode})")
        for label, process in [("the gateway", self.gateway)] + [(f"rsg_{l}", t) for l, t in self.tools.items()]:
            rss = resident_kb(process.pid)
            check(rss < RUNAWAY_KB, f"{label}'s resident memory reached {rss // 1024} MB {what}")

    def wait_progress(self, what, frames=300):
        """The gateway publishes `frames` more and the reader gets as many, every tool still running."""
        published, samples = self.published(), self.samples()

        def progressed():
            self.alive(what)
            return self.published() >= published + frames and self.samples() >= samples + frames
        wait_for(progressed, f"the gateway to publish and the reader to get {frames} samples {what}", timeout_s=10)

    def screened(self):
        """{reason: count} of the gateway's rsg_dds_screen_dropped_total (empty without the series)."""
        reply = http_get(self.metrics_port, "/metrics")
        check(reply is not None and reply[0] == 200, f"/metrics did not answer: {reply}")
        return {labels.get("reason", ""): value for name, labels, value in parse_samples(reply[1])
                if name == "rsg_dds_screen_dropped_total"}

    def run(self, flaw, way):
        what = f"{flaw.name} sent {way}"
        before, rss_before = self.screened(), resident_kb(self.gateway.pid)
        sent = attack(flaw, way, self.h.domain)
        time.sleep(0.2)
        self.wait_progress(f"after {what}")
        growth = resident_kb(self.gateway.pid) - self.rss0
        dropped = {reason: int(count - before.get(reason, 0)) for reason, count in self.screened().items()
                   if count > before.get(reason, 0)}
        print(f"[fastdds_flaws] rsg, {what} ({sent} datagrams): the gateway publishes, the reader gets its "
              f"samples, rsg_echo, rsg_record and rsg_view run; gateway resident memory {growth:+d} kB; "
              f"its screen dropped {dropped or 'nothing'}", flush=True)
        if flaw.kind == "held":
            held = resident_kb(self.gateway.pid) - rss_before
            check(held < HELD_LIMIT_KB, f"{what} added {held} kB to the gateway (limit {HELD_LIMIT_KB} kB)")

    def finish(self):
        h = self.h
        late = h.start("late", [h.binary("rsg_echo"), "--domain", str(h.domain), "--json", "--count", "200",
                                "--timeout", "15"])
        check(h.wait("late", late, 30) == 0, "a reader started after the attacks did not get 200 samples")
        growth = resident_kb(self.gateway.pid) - self.rss0
        tools = ", ".join(f"rsg_{label} {resident_kb(tool.pid) - self.tools_rss0[label]:+d} kB"
                          for label, tool in self.tools.items())
        print(f"[fastdds_flaws] rsg: a reader started after every attack matched and got 200 samples; resident "
              f"memory over every attack: the gateway {growth:+d} kB, {tools}", flush=True)
        check(growth < GATEWAY_GROWTH_LIMIT_KB,
              f"the gateway's resident memory grew by {growth} kB (limit {GATEWAY_GROWTH_LIMIT_KB} kB)")
        self.alive("after the attacks")
        check(h.stop("gateway", self.gateway) == 0, "the gateway did not exit 0 on SIGTERM")


def body(h):
    only = os.environ.get("RSG_FLAWS_ONLY", "")
    rows = os.environ.get("RSG_FLAWS_ROWS", "")
    flaws = [f for f in FLAWS if not rows or f.cve in rows.split(",")]
    control = Control(h) if only != "rsg" else None
    gateway = Gateway(h) if only != "control" else None
    for flaw in flaws:
        print(f"[fastdds_flaws] {flaw.name}: {flaw.what}", flush=True)
        for way in flaw.ways:
            if control:
                control.run(flaw, way)
        for way in flaw.ways:
            if gateway:
                gateway.run(flaw, way)
    if control:
        control.check_shown()
    if gateway:
        gateway.finish()


if __name__ == "__main__":
    sys.exit(main("fastdds_flaws", body))
