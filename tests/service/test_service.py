"""The Debian package under a real systemd as PID 1 (make test-service, docs/service.md).

One container of tests/service/Containerfile (debootstrap's Debian 12 plus systemd, systemd-sysv
and dbus), run with `podman run --systemd=always --network host --ipc host`: the gateway inside
binds loopback and publishes on the host's network and /dev/shm, where this build's rsg_sim and
rsg_echo run as the robot and a reader outside the container. The steps run in order, each on what
the ones before left:

  install       apt-get installs the older .deb (its Depends resolved from the mirror of the
                image's apt sources); the file system is listed before, for `purge`
  ready         the instance robot1 enabled and started: `active` only after READY=1, i.e. the
                first time systemd says active, the stats file exists and the UDP port is bound;
                systemd's StatusText is the gateway's STATUS= line; the stats file is mode 0640,
                group rsg: a user in that group reads it, another is refused; every
                Documentation= of the unit (the man page, the guides) is installed
  frames        frames sent from the host arrive exact at rsg_echo --json on the host; the
                gateway's "link up" is in the journal at priority info, not among the warnings,
                with the journal's time only (no "[2026-..." of the gateway's own)
  status_cause  datagrams from 127.0.0.2, outside allow-from: systemd's StatusText says "link
                down: ignoring N datagrams/s from outside --allow-from"
  dds_attacks   (after upgrade) the Fast DDS attacks of tests/support/dds_attacks.py from the host (the 84-byte
                statistics datagram on every port of the domain, two readers on a unicast and a
                multicast locator, 3,000 random RTPS datagrams): the same process keeps running
                (no restart), rsg_dds_guard_total counts what its guard did, frames arrive exact
  fastdds_flaws every published Fast DDS flaw of tests/support/fastdds_flaws.py from the host,
                unicast and to the discovery multicast group (integration.fastdds_flaws has their
                controls): the same process keeps running (no restart), and a reader started after
                them gets frames exact
  sigkill       the gateway killed with SIGKILL: systemd restarts it, and the same rsg_echo
                receives the next frames exact
  watchdog      the gateway frozen with SIGSTOP: systemd's watchdog kills it ("Watchdog timeout" in
                the journal) within WatchdogSec (5 s) + WATCHDOG_MARGIN_S, and restarts it
  upgrade       apt-get install of the current .deb over the older one: the running instance is
                restarted by postinst on the new version and frames arrive exact; a second
                instance whose file was broken meanwhile does not come back: postinst names it
                (and the one it restarted), the install fails, and `dpkg --configure -a`
                finishes once the file is fixed
  ros2_type_hash  a second instance with --ros2 and the standard topics: a ROS 2 Jazzy
                rclpy node on the host (make deps' ROS 2 environment) sees rosidl's RIHS01 hash on all
                five writers
  broken        an instance with a configuration the gateway refuses: its start fails, the error
                is in `journalctl -u` at priority err, the exit status is 2 and systemd does not
                start it again (RestartPreventExitStatus=2): one start, the unit failed
  purge         apt-get purge: no process, unit, file, directory, user or group left that was not
                there before the install (the Depends stay: the listing is taken after apt-get
                satisfy installed them)

    tests/service/run.sh        # builds the package, the image, then runs this (make test-service)
    test_service.py --engine "podman --runtime runc" --image rsg-service-test \
                    --deb NEW.deb --old-deb OLD.deb --bin BUILD/bin
"""

import argparse
import fcntl
import json
import os
import re
import secrets
import shlex
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "support"))
from harness import TestFailure, check, free_tcp_port, free_udp_port, read_json_lines, wait_for  # noqa: E402
from metrics_support import http_get, parse_samples, value_of  # noqa: E402
from dds_attacks import (TWO_LOCATORS_PROFILE, TWO_LOCATORS_XML, guard_counts, one_datagram,  # noqa: E402
                         random_datagrams, send_to_domain)
from fastdds_flaws import attack_every  # noqa: E402

UNIT = "rsg-gateway@robot1.service"
BROKEN = "rsg-gateway@broken.service"
ROS2_INSTANCE = "ros2"  # a second instance, with --ros2 and the standard topics
ROS2_UNIT = f"rsg-gateway@{ROS2_INSTANCE}.service"
LOST_INSTANCE = "robot3"  # an instance that does not come back after the upgrade
LOST_UNIT = f"rsg-gateway@{LOST_INSTANCE}.service"
STATS = "/run/rsg/robot1/stats.json"
WATCHDOG_S = 5  # WatchdogSec= of deploy/systemd/rsg-gateway@.service
# What the watchdog kill may take beyond WatchdogSec: the SIGABRT's core dump and systemd's tick.
WATCHDOG_MARGIN_S = 10
FRAMES = 300
RATE = 500
# DDS domains no other suite uses: ctest's are 20-99 (tests/support/test_domain.py), make test-image's
# 210-230. A lock file per domain keeps two runs on this machine apart; the partition, random per
# run, keeps any other participant's samples out.
DOMAINS = (231, 232)
# Left out of the before/after comparison: what apt, dpkg, journald and systemd keep for themselves.
VOLATILE = re.compile(r"^(/var/lib/(apt|dpkg|systemd)|/var/cache|/var/log|/run/(systemd|log|dbus|lock|user)"
                      r"|/etc/ld\.so\.cache)(/|$)")


def claim_domain():
    for domain in DOMAINS:
        lock = open(f"/tmp/rsg-test-service-domain-{domain}.lock", "w")
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return domain, lock
        except BlockingIOError:
            lock.close()
    raise TestFailure(f"every domain of {DOMAINS} is held by another make test-service on this machine")


class Box:
    """The container: systemd as PID 1, the host's network and /dev/shm."""

    def __init__(self, engine, image, workdir, debs):
        self.engine = shlex.split(engine)
        self.name = f"rsg-service-test-{secrets.token_hex(4)}"
        self.workdir = workdir
        run = subprocess.run([*self.engine, "run", "-d", "--name", self.name, "--systemd=always", "--network", "host",
                              "--ipc", "host", "-v", f"{debs}:/debs:ro", image], capture_output=True, text=True, timeout=120)
        check(run.returncode == 0, f"podman run: {run.stderr.strip()}")
        state = wait_for(lambda: self.state_of_system(), "systemd in the container to finish booting", timeout_s=120,
                         interval_s=0.5)
        check(state in ("running", "degraded"), f"systemd in the container is {state}: {self.sh('systemctl --failed')}")
        print(f"[service] container {self.name}: systemd {state}", flush=True)

    def state_of_system(self):
        state = self.sh("systemctl is-system-running", check_status=False).strip()
        return state if state not in ("initializing", "starting", "") else None

    def sh(self, command, check_status=True, timeout_s=300):
        result = subprocess.run([*self.engine, "exec", self.name, "sh", "-c", command], capture_output=True,
                                text=True, timeout=timeout_s)
        if check_status:
            check(result.returncode == 0, f"in the container, `{command}` exited {result.returncode}:\n"
                                          f"{result.stdout[-2000:]}{result.stderr[-2000:]}")
        return result.stdout

    def show(self, unit, prop):
        return self.sh(f"systemctl show -p {prop} --value {unit}").strip()

    def main_pid(self, unit=UNIT):
        return int(self.show(unit, "MainPID") or 0)

    def stats(self):
        text = self.sh(f"cat {STATS} 2>/dev/null", check_status=False)
        try:
            return json.loads(text)
        except ValueError:
            return None

    def journal(self, unit):
        return self.sh(f"journalctl -u {unit} --no-pager -o cat", check_status=False)

    def listing(self):
        """Every path on the container's file system but the volatile ones, and the users and groups."""
        paths = self.sh("find / -xdev \\( -path /proc -o -path /sys -o -path /dev -o -path /debs \\) -prune "
                        "-o -print")
        kept = {path for path in paths.splitlines() if not VOLATILE.match(path)}
        return kept, self.sh("getent passwd; getent group")

    def remove(self):
        subprocess.run([*self.engine, "rm", "-f", "-t", "5", self.name], capture_output=True, timeout=120)


class Run:
    def __init__(self, args):
        self.args = args
        self.bin = Path(args.bin)
        self.dir = Path(tempfile.mkdtemp(prefix="rsg_service_"))
        self.domain, self._lock = claim_domain()
        self.partition = f"svc-{secrets.token_hex(4)}"
        self.port = free_udp_port()
        self.metrics_port = free_tcp_port()
        self.echo = None
        self.echo_err = self.dir / "echo.err"
        self.echo_out = self.dir / "echo.out"
        self.sent = []
        self.box = None
        self.before = None

    def deb_version(self, deb):
        return subprocess.run(["dpkg-deb", "-f", deb, "Version"], capture_output=True, text=True,
                              check=True).stdout.strip()

    def config(self):
        return (f"listen: 127.0.0.1:{self.port}\nallow-from: [127.0.0.1]\nexpected-rate: {RATE}\n"
                f"domain: {self.domain}\npartition: {self.partition}\nstats-file: {STATS}\n"
                f"metrics: 127.0.0.1:{self.metrics_port}\n")

    def start_echo(self, count):
        self.echo = subprocess.Popen(
            [str(self.bin / "rsg_echo"), "--domain", str(self.domain), "--partition", self.partition, "--json",
             "--count", str(count), "--timeout", "120"],
            stdout=open(self.echo_out, "wb"), stderr=open(self.echo_err, "wb"))

    def echo_matches(self):
        text = self.echo_err.read_text(errors="replace") if self.echo_err.exists() else ""
        return [int(n) for n in re.findall(r"matched (\d+) writers? of", text)]

    def wait_matched(self, matches_before):
        """Both sides of discovery: the gateway counts a reader, and the echo matched a new writer
        (its count went up since `matches_before` lines: a killed gateway's writer lingers until its
        lease ends, so the new one may make it 2)."""
        wait_for(lambda: (self.box.stats() or {}).get("state_readers", 0) >= 1, "the gateway to match rsg_echo",
                 timeout_s=60, interval_s=0.5)

        def new_writer():
            counts = self.echo_matches()
            previous = counts[matches_before - 1] if matches_before else 0
            for count in counts[matches_before:]:
                if count > previous:
                    return True
                previous = count
            return False
        wait_for(new_writer, "rsg_echo to match the gateway's writer", timeout_s=60, interval_s=0.2)

    def send_and_check(self, label):
        """FRAMES frames from rsg_sim on the host; rsg_echo prints each exact, in order."""
        record = self.dir / f"{label}.jsonl"
        sim = subprocess.run([str(self.bin / "rsg_sim"), "--to", f"127.0.0.1:{self.port}", "--rate", str(RATE),
                              "--count", str(FRAMES), "--record", str(record)], capture_output=True, text=True,
                             timeout=60)
        check(sim.returncode == 0, f"rsg_sim: {sim.stderr.strip()}")
        sent = read_json_lines(record)
        check(len(sent) == FRAMES, f"rsg_sim recorded {len(sent)} frames, not {FRAMES}")
        self.sent += sent
        expected = len(self.sent)
        wait_for(lambda: len(read_json_lines(self.echo_out)) >= expected,
                 f"rsg_echo to print {expected} samples (has {len(read_json_lines(self.echo_out))})", timeout_s=60,
                 interval_s=0.2)
        received = read_json_lines(self.echo_out)
        check(len(received) == expected, f"rsg_echo printed {len(received)} samples, {expected} frames were sent")
        for index, (want, got) in enumerate(zip(self.sent, received)):
            check(want == got, f"sample {index} differs from the frame sent:\n  sent {want}\n  got  {got}")
        print(f"[service] {label}: {FRAMES} frames exact at rsg_echo on the host ({expected} in all)", flush=True)

    def wait_restarted(self, old_pid, what, timeout_s):
        def restarted():
            pid = self.box.main_pid()
            return pid if pid not in (0, old_pid) and self.box.show(UNIT, "ActiveState") == "active" else None
        return wait_for(restarted, what, timeout_s=timeout_s, interval_s=0.2)

    # --- the steps -------------------------------------------------------------------------------

    def install(self):
        self.box = Box(self.args.engine, self.args.image, self.dir, Path(self.args.deb).parent)
        new, old = Path(self.args.deb), Path(self.args.old_deb)
        check(new.parent.resolve() == old.parent.resolve(), "--deb and --old-deb must be in one directory")
        depends = subprocess.run(["dpkg-deb", "-f", str(new), "Depends"], capture_output=True, text=True,
                                 check=True).stdout.strip()
        self.box.sh("apt-get update -qq")
        # The Depends first, so that the listing below differs from the one after the purge only by
        # what the package (and systemd for it) made.
        self.box.sh(f"DEBIAN_FRONTEND=noninteractive apt-get satisfy -y -qq --no-install-recommends {shlex.quote(depends)}")
        self.before = self.box.listing()
        self.box.sh(f"DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends /debs/{old.name}")
        version = self.box.sh("dpkg-query -W -f '${Version}' rsg")
        check(version == self.deb_version(old), f"installed rsg {version}, not {self.deb_version(old)}")
        check(self.box.sh("test -f /lib/systemd/system/rsg-gateway@.service -o -f "
                          "/usr/lib/systemd/system/rsg-gateway@.service && echo yes", check_status=False).strip() == "yes",
              "the package installed no rsg-gateway@.service")
        check("robot1.yaml" in self.box.sh("ls /etc/rsg"), "the package installed no /etc/rsg/robot1.yaml")
        print(f"[service] install: rsg {version} installed by apt-get (Depends: {depends})", flush=True)

    def ready(self):
        self.box.sh(f"cat > /etc/rsg/robot1.yaml <<'EOF'\n{self.config()}EOF")
        self.box.sh(f"systemctl enable {UNIT}")
        self.box.sh(f"systemctl start --no-block {UNIT}")
        port_hex = f":{self.port:04X} "
        seen = []

        def active():
            state = self.box.show(UNIT, "ActiveState")
            seen.append(state)
            if state == "failed":
                raise TestFailure(f"{UNIT} failed to start:\n{self.box.journal(UNIT)[-2000:]}")
            if state != "active":
                return None
            # The first time systemd says active: what the gateway does before READY=1 is done.
            bound = port_hex in self.box.sh("cat /proc/net/udp /proc/net/udp6")
            stats = self.box.stats()
            return (bound, stats)
        bound, stats = wait_for(active, f"{UNIT} to become active", timeout_s=60, interval_s=0.05)
        check(bound, f"{UNIT} was active before its UDP port {self.port} was bound")
        check(stats is not None, f"{UNIT} was active before its stats file {STATS} was written")
        check(self.box.show(UNIT, "Type") == "notify", f"{UNIT} is not Type=notify")
        # The memory bound and the restart policy (never given up) as systemd read them.
        memory_max = self.box.show(UNIT, "MemoryMax")
        check(memory_max.isdigit(), f"{UNIT}'s MemoryMax is {memory_max!r}, not a bound")
        check(self.box.show(UNIT, "StartLimitIntervalUSec") in ("0", "0s"),
              f"{UNIT} has a start limit: {self.box.show(UNIT, 'StartLimitIntervalUSec')}")
        status = wait_for(lambda: self.box.show(UNIT, "StatusText"), "the gateway's STATUS= line", timeout_s=10)
        # The stats file: readable by the group rsg (the unit's Group=), by no other user. setpriv
        # runs as IDs no user has, so that the users and groups stay as they were for `purge`.
        mode = self.box.sh(f"stat -c '%a %G' {STATS}").strip()
        check(mode == "640 rsg", f"{STATS} is '{mode}', not '640 rsg'")
        gid = self.box.sh("getent group rsg | cut -d: -f3").strip()
        as_operator = self.box.sh(f"setpriv --reuid 4242 --regid 4242 --groups {gid} cat {STATS}",
                                  check_status=False)
        check("frames_published" in as_operator, f"a user of the group rsg cannot read {STATS}: {as_operator!r}")
        other = subprocess.run([*self.box.engine, "exec", self.box.name, "setpriv", "--reuid", "4242", "--regid",
                                "4242", "--clear-groups", "cat", STATS], capture_output=True, text=True, timeout=60)
        check(other.returncode != 0 and "Permission denied" in other.stderr,
              f"a user outside the group rsg read {STATS}: exit {other.returncode} {other.stderr!r}")
        # Documentation= names what the package installs.
        # systemctl show quotes a value with parentheses ("man:rsg_gateway(1)").
        documentation = [uri.strip('"') for uri in self.box.show(UNIT, "Documentation").split()]
        check(any(d.startswith("man:") for d in documentation) and any(d.startswith("file:") for d in documentation),
              f"Documentation= {documentation}")
        # Checked against the package's contents: the container, like Debian's minimal images, may
        # leave /usr/share/man and /usr/share/doc out when dpkg unpacks (path-exclude).
        contents = subprocess.run(["dpkg-deb", "-c", self.args.deb], capture_output=True, text=True,
                                  check=True).stdout
        for uri in documentation:
            path = (f"/usr/share/man/man1/{uri[4:].split('(')[0]}.1.gz" if uri.startswith("man:")
                    else uri[len("file:"):] if uri.startswith("file:") else None)
            check(path is not None and f".{path}\n" in contents, f"Documentation={uri} is not in the package ({path})")
        print(f"[service] ready: states seen {sorted(set(seen))}; active with the port bound and the stats file "
              f"written; StatusText: {status}; {STATS} {mode}, read by the group rsg only; Documentation= "
              f"{' '.join(documentation)} installed", flush=True)

    def frames(self):
        self.start_echo(4 * FRAMES)
        self.wait_matched(0)
        self.send_and_check("frames")
        # The journal has the gateway's info lines at priority info, not among the warnings.
        infos = self.box.sh(f"journalctl -u {UNIT} -p info --no-pager -o cat")
        warnings = self.box.sh(f"journalctl -u {UNIT} -p warning --no-pager -o cat")
        check("link up" in infos and "link up" not in warnings,
              f"'link up' is not an info line of the journal:\n{infos[-1500:]}\n-- warnings:\n{warnings[-1500:]}")
        # One time per line: the journal's. The gateway's lines carry none of their own.
        stamped = [line for line in infos.splitlines() if re.match(r"^\[\d{4}-\d\d-\d\d ", line)]
        check(not stamped, f"journal lines with the gateway's own time as well: {stamped[:3]}")

    def status_cause(self):
        """Datagrams from 127.0.0.2, which allow-from [127.0.0.1] refuses, while the link is down:
        `systemctl status` names them."""
        wait_for(lambda: self.box.show(UNIT, "StatusText").startswith("link down"), "the link to go down",
                 timeout_s=10)
        sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sender.bind(("127.0.0.2", 0))
        found = None
        deadline = time.monotonic() + 20
        try:
            while found is None and time.monotonic() < deadline:
                for _ in range(50):  # about 1000 a second
                    sender.sendto(b"not from the robot", ("127.0.0.1", self.port))
                    time.sleep(0.001)
                status = self.box.show(UNIT, "StatusText")
                if re.match(r"link down: ignoring \d+ datagrams/s from outside --allow-from", status):
                    found = status
        finally:
            sender.close()
        check(found is not None, f"StatusText never named the refused datagrams: {self.box.show(UNIT, 'StatusText')}")
        print(f"[service] status_cause: StatusText: {found}", flush=True)

    def dds_attacks(self):
        pid = self.box.main_pid()
        restarts = self.box.show(UNIT, "NRestarts")

        def same_process(what):
            check(self.box.main_pid() == pid and self.box.show(UNIT, "ActiveState") == "active",
                  f"the gateway did not survive {what}:\n{self.box.journal(UNIT)[-2000:]}")
            check(self.box.show(UNIT, "NRestarts") == restarts, f"systemd restarted the gateway after {what}")

        def guard():
            reply = http_get(self.metrics_port, "/metrics")
            check(reply is not None and reply[0] == 200, f"/metrics did not answer: {reply}")
            return guard_counts(parse_samples(reply[1]), value_of)

        send_to_domain(self.domain, [one_datagram()] * 3)
        time.sleep(0.5)
        same_process("the 84-byte statistics datagram")
        wait_for(lambda: guard()["statistics_misplaced"] >= 1, "rsg_dds_guard_total to count the misplaced statistics submessage",
             timeout_s=30)

        profile = self.dir / "two_locators.xml"
        profile.write_text(TWO_LOCATORS_XML)
        sim = subprocess.Popen([str(self.bin / "rsg_sim"), "--to", f"127.0.0.1:{self.port}", "--rate", str(RATE),
                                "--duration", "60"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            readers = []
            for i in range(3):  # side by side: the second one to match is the one Fast DDS sends to unopened
                readers.append(subprocess.Popen(
                    [str(self.bin / "rsg_echo"), "--domain", str(self.domain), "--partition", self.partition,
                     "--json", "--count", "1000", "--timeout", "40", "--profiles", str(ROOT / "xml_profiles"),
                     "--profiles", str(profile), "--participant-profile", TWO_LOCATORS_PROFILE],
                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True))
                time.sleep(0.7)
            for i, reader in enumerate(readers):
                _, err = reader.communicate(timeout=60)
                check(reader.returncode == 0, f"reader {i} on two locators did not get 1000 samples: {err[-500:]}")
        finally:
            sim.terminate()
            sim.wait()
        same_process("two readers on a unicast and a multicast locator")
        wait_for(lambda: guard()["send_channel_opened"] >= 1, "rsg_dds_guard_total to count the opened send channel",
             timeout_s=30)

        send_to_domain(self.domain, random_datagrams(3000))
        time.sleep(0.5)
        same_process("3,000 random RTPS datagrams")
        # A fresh reader (the one of the steps before has finished): frames still arrive exact.
        self.sent = []
        self.start_echo(FRAMES)
        self.wait_matched(0)
        self.send_and_check("dds_attacks")
        check(self.echo.wait(timeout=60) == 0, f"rsg_echo exited non-zero: {self.echo_err.read_text()[-500:]}")
        print(f"[service] dds_attacks: pid {pid} kept running, no restart; guard {guard()}", flush=True)

    def fastdds_flaws(self):
        pid = self.box.main_pid()
        restarts = self.box.show(UNIT, "NRestarts")

        def same_process(what):
            check(self.box.main_pid() == pid and self.box.show(UNIT, "ActiveState") == "active",
                  f"the gateway did not survive {what}:\n{self.box.journal(UNIT)[-2000:]}")

        sent = attack_every(self.domain, same_process)
        check(self.box.show(UNIT, "NRestarts") == restarts, "systemd restarted the gateway after the published flaws")
        self.sent = []
        self.start_echo(FRAMES)
        self.wait_matched(0)
        self.send_and_check("fastdds_flaws")
        check(self.echo.wait(timeout=60) == 0, f"rsg_echo exited non-zero: {self.echo_err.read_text()[-500:]}")
        print(f"[service] fastdds_flaws: {sent} datagrams; pid {pid} kept running, no restart; a reader started "
              "after them got every frame", flush=True)

    def sigkill(self):
        pid = self.box.main_pid()
        restarts = int(self.box.show(UNIT, "NRestarts"))
        matches = len(self.echo_matches())
        self.box.sh(f"kill -KILL {pid}")
        new_pid = self.wait_restarted(pid, "systemd to restart the gateway after SIGKILL", timeout_s=60)
        check(int(self.box.show(UNIT, "NRestarts")) == restarts + 1, "NRestarts did not count the restart")
        self.wait_matched(matches)
        self.send_and_check("sigkill")
        print(f"[service] sigkill: pid {pid} killed, restarted as {new_pid}, rsg_echo resumed", flush=True)

    def watchdog(self):
        pid = self.box.main_pid()
        matches = len(self.echo_matches())
        journal_before = self.box.journal(UNIT).count("Watchdog timeout")
        self.box.sh(f"kill -STOP {pid}")
        frozen = time.monotonic()
        bound = WATCHDOG_S + WATCHDOG_MARGIN_S

        def killed():
            return self.box.journal(UNIT).count("Watchdog timeout") > journal_before
        wait_for(killed, f"systemd's watchdog to kill the frozen gateway (WatchdogSec={WATCHDOG_S}s)",
                 timeout_s=bound, interval_s=0.2)
        took = time.monotonic() - frozen
        new_pid = self.wait_restarted(pid, "systemd to restart the gateway after the watchdog", timeout_s=60)
        self.wait_matched(matches)
        self.send_and_check("watchdog")
        print(f"[service] watchdog: pid {pid} frozen, killed by the watchdog {took:.1f} s later (bound "
              f"{WATCHDOG_S} + {WATCHDOG_MARGIN_S} s), restarted as {new_pid}, rsg_echo resumed", flush=True)

    def upgrade(self):
        pid = self.box.main_pid()
        matches = len(self.echo_matches())
        new = Path(self.args.deb)
        # A second instance that will not come back: running on a good file, which is then broken
        # (an unknown key) before the upgrade restarts it.
        self.box.sh(f"printf 'listen: 127.0.0.1:{free_udp_port()}\\ndomain: {self.domain}\\n' > /etc/rsg/{LOST_INSTANCE}.yaml"
                    f" && systemctl start {LOST_UNIT}")
        self.box.sh(f"printf 'no-such-key: 1\\n' >> /etc/rsg/{LOST_INSTANCE}.yaml")
        install = subprocess.run(
            [*self.box.engine, "exec", self.box.name, "sh", "-c",
             f"DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "
             f"-o Dpkg::Options::=--force-confold /debs/{new.name}"], capture_output=True, text=True, timeout=600)
        said = install.stdout + install.stderr
        check(install.returncode != 0, f"the upgrade succeeded though {LOST_UNIT} did not come back:\n{said[-2000:]}")
        check(f"{LOST_UNIT} did not come back after the upgrade" in said and f"{UNIT} restarted on the new version" in said,
              f"postinst did not name the instance that failed and the one restarted:\n{said[-2000:]}")
        # Fixed, dpkg finishes the configuration.
        self.box.sh(f"systemctl stop {LOST_UNIT}; systemctl reset-failed {LOST_UNIT}; rm /etc/rsg/{LOST_INSTANCE}.yaml; "
                    "dpkg --configure -a")
        version = self.box.sh("dpkg-query -W -f '${Version}' rsg")
        check(version == self.deb_version(new), f"after the upgrade rsg {version} is installed, not {self.deb_version(new)}")
        check(self.box.sh("cat /etc/rsg/robot1.yaml") == self.config(), "the upgrade changed the edited robot1.yaml")
        new_pid = self.wait_restarted(pid, "postinst to restart the running instance", timeout_s=60)
        self.wait_matched(matches)
        self.send_and_check("upgrade")
        check(self.echo.wait(timeout=60) == 0, f"rsg_echo exited non-zero: {self.echo_err.read_text()[-500:]}")
        print(f"[service] upgrade: {self.deb_version(Path(self.args.old_deb))} -> {version}, pid {pid} restarted as "
              f"{new_pid}, the edited conffile kept; postinst named {LOST_UNIT}, which did not come back, and "
              f"exited non-zero; dpkg --configure -a finished once it was fixed", flush=True)

    def ros2_type_hash(self):
        """The packaged gateway as a second instance with --ros2 and the standard topics: a real rclpy
        node on the host (make deps' ROS 2 environment) sees rosidl's RIHS01 type hash on every
        ROS 2 writer, computed at the package's build without ROS 2: a ROS 2 Jazzy node."""
        sys.path.insert(0, str(ROOT / "tests" / "ros2"))
        from rclpy_common import RosEnv, check_rosidl_type_hashes  # noqa: E402 (the ROS 2 environment only here)
        self.box.sh(f"printf 'listen: 127.0.0.1:{free_udp_port()}\\ndomain: {self.domain}\\nros2: true\\n"
                    f"joint-states: \"100\"\\ntf: \"every:5\"\\nexternal-wrench: \"50\"\\n' > /etc/rsg/{ROS2_INSTANCE}.yaml")
        self.box.sh(f"systemctl start {ROS2_UNIT}")
        try:
            checked = {distro: check_rosidl_type_hashes(RosEnv(self.domain, distro)) for distro in ("jazzy",)}
        finally:
            self.box.sh(f"systemctl stop {ROS2_UNIT}; rm -f /etc/rsg/{ROS2_INSTANCE}.yaml", check_status=False)
        print(f"[service] ros2_type_hash: rosidl's hash on all ROS 2 writers of the packaged gateway "
              f"({ROS2_UNIT}), writers checked per distribution: {checked}", flush=True)

    def broken(self):
        self.box.sh("printf 'listen: 127.0.0.1:1\\nno-such-key: 1\\n' > /etc/rsg/broken.yaml")
        start = subprocess.run([*self.box.engine, "exec", self.box.name, "systemctl", "start", BROKEN],
                               capture_output=True, text=True, timeout=120)
        check(start.returncode != 0, f"systemctl start {BROKEN} succeeded")

        wait_for(lambda: self.box.show(BROKEN, "ActiveState") == "failed", f"{BROKEN} to fail", timeout_s=60,
                 interval_s=0.5)
        status = self.box.show(BROKEN, "ExecMainStatus")
        check(status == "2", f"{BROKEN} exited {status}, not 2 (a configuration error)")
        journal = self.box.journal(BROKEN)
        check("no-such-key" in journal, f"the gateway's error is not in journalctl -u {BROKEN}:\n{journal[-2000:]}")
        # ... at the error priority (the gateway's <3> prefix on the journal's stream).
        errors = self.box.sh(f"journalctl -u {BROKEN} -p err --no-pager -o cat", check_status=False)
        check("no-such-key" in errors, f"the gateway's error is not at priority err in the journal:\n{errors[-2000:]}")
        time.sleep(3 * 2)  # three RestartSec: a restart would have come by now
        starts = self.box.journal(BROKEN).count("Starting rsg-gateway@broken.service")
        check(starts == 1, f"{starts} starts of {BROKEN}: a configuration error was restarted (RestartPreventExitStatus=2)")
        check(self.box.show(BROKEN, "NRestarts") == "0", f"{BROKEN} was restarted")
        check(self.box.show(BROKEN, "ActiveState") == "failed", f"{BROKEN} is no longer failed")
        line = next((l for l in journal.splitlines() if "no-such-key" in l), "")
        print(f"[service] broken: systemctl start failed, exit 2, one start and no restart; "
              f"journal: {line.strip()[:160]}", flush=True)
        self.box.sh(f"systemctl reset-failed {BROKEN}; rm /etc/rsg/broken.yaml")

    def purge(self):
        self.box.sh("DEBIAN_FRONTEND=noninteractive apt-get purge -y -qq rsg")
        check(self.box.sh("pgrep -x rsg_gateway", check_status=False).strip() == "",
              "an rsg_gateway still runs after the purge")
        units = self.box.sh("systemctl list-units --all --plain --no-legend 'rsg-gateway@*'", check_status=False)
        check(units.strip() == "", f"units left after the purge:\n{units}")
        paths, users = self.box.listing()
        before_paths, before_users = self.before
        check(users == before_users, f"users or groups differ after the purge:\n{users}")
        left, gone = sorted(paths - before_paths), sorted(before_paths - paths)
        check(not left, "left behind by the purge:\n  " + "\n  ".join(left[:50]))
        check(not gone, "removed by the install and purge, though there before:\n  " + "\n  ".join(gone[:50]))
        print(f"[service] purge: nothing left ({len(paths)} paths compared, users and groups the same)", flush=True)

    def cleanup(self, keep):
        if self.echo is not None and self.echo.poll() is None:
            self.echo.kill()
            self.echo.wait()
        if self.box is not None:
            if not keep:
                (self.dir / "journal.txt").write_text(self.box.sh("journalctl --no-pager", check_status=False))
            self.box.remove()
        subprocess.run(["fastdds", "shm", "clean"], capture_output=True)


STEPS = ["install", "ready", "frames", "status_cause", "sigkill", "watchdog", "upgrade", "dds_attacks",
         "fastdds_flaws", "ros2_type_hash", "broken", "purge"]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--engine", required=True, help='the engine command: "podman --runtime runc"')
    parser.add_argument("--image", required=True)
    parser.add_argument("--deb", required=True, help="the package of this build")
    parser.add_argument("--old-deb", required=True, help="the same with a lower version (the upgrade's start)")
    parser.add_argument("--bin", required=True, help="rsg_sim and rsg_echo of this build, run on the host")
    args = parser.parse_args()
    run = Run(args)
    passed = failed = 0
    ok = False
    try:
        for step in STEPS:
            start = time.monotonic()
            try:
                getattr(run, step)()
            except (TestFailure, subprocess.TimeoutExpired) as failure:
                print(f"[service.{step}] FAILED in {time.monotonic() - start:.0f} s: {failure}", flush=True)
                failed += 1
                break
            print(f"[service.{step}] passed in {time.monotonic() - start:.0f} s", flush=True)
            passed += 1
        ok = failed == 0
    finally:
        if not ok:
            journal = run.box.sh("journalctl --no-pager -n 200", check_status=False) if run.box else ""
            print(f"--- the container's journal (last 200 lines)\n{journal}\n(outputs are in {run.dir})")
        run.cleanup(keep=not ok)
    not_run = len(STEPS) - passed - failed
    failed += not_run  # a step that could not run after a failure counts as failed, never as skipped
    print(f"service: {passed} passed, {failed} failed")
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
