"""deploy/systemd: `systemd-analyze verify` accepts rsg-gateway@.service (alone and with the
realtime.conf drop-in) with no warning, `systemd-analyze security` rates it OK (exposure at most
2.0; the figure is in docs/service.md), it keeps the promises docs/service.md makes (Type=notify,
a watchdog, restarts never given up but none after a configuration error, a memory bound, a
dynamic user with the group `rsg`, a read-only system, the installed documentation), and the real
rsg_gateway runs the example configuration robot1.yaml.

Two robots from copied files, as docs/service.md says to start a second one: robot2.yaml a copy
of robot1.yaml with its own ports, both run with the unit's ExecStart= (%i replaced): each in the
partition of its instance name, with the stats file and pcap-dir of its own unit directories
(--check-config says so, as the unit will run them), and neither sees the other's writer. The
control: a copy that keeps `partition: robot1` (the example before --instance) puts both in one
partition, and both gateways say so. Fails (never skips) without systemd-analyze."""

import re
import shutil
import subprocess
import sys
from pathlib import Path

from harness import TestFailure, check, free_tcp_port, free_udp_port, main, wait_for, wait_for_stats  # noqa: E402
from metrics_support import http_get, parse_samples, value_of  # noqa: E402

DEPLOY = Path(__file__).resolve().parents[2] / "deploy" / "systemd"
MAX_EXPOSURE = 2.0
PROMISES = ["Type=notify", "NotifyAccess=main", "WatchdogSec=", "Restart=on-failure", "StartLimitIntervalSec=0",
            "RestartSec=", "RestartPreventExitStatus=2", "MemoryMax=", "DynamicUser=yes", "Group=rsg",
            "Documentation=man:rsg_gateway(1)",
            # The directories rsg_gateway --instance and --check-config take for the unit's
            # (src/gateway/config.hpp: kUnitRuntimeRoot, kUnitStateRoot).
            "RuntimeDirectory=rsg/%i", "StateDirectory=rsg/%i", "ProtectSystem=strict", "NoNewPrivileges=yes",
            "ExecStart=/usr/bin/rsg_gateway --config /etc/rsg/%i.yaml --name %i --instance %i",
            "ExecReload=/bin/kill -HUP $MAINPID"]
# The example's flight recorder is bounded (docs/configuration.md): safe to leave running.
BOUNDED_RECORDER = ["pcap-min-interval:", "pcap-max-files:", "pcap-max-mb:"]


def settings(path):
    return [line.strip() for line in path.read_text().splitlines() if line.strip() and not line.startswith("#")]


def body(h):
    analyze = shutil.which("systemd-analyze")
    if analyze is None:
        raise TestFailure("systemd-analyze is not installed: apt-get install systemd (docker/packages/test.txt)")
    unit = DEPLOY / "rsg-gateway@.service"
    lines = settings(unit)
    for promise in PROMISES:
        check(any(line.startswith(promise) for line in lines), f"{unit.name} lacks {promise}")

    # The unit as installed, but starting the binary of this build (verify checks ExecStart exists).
    gateway_bin = str(Path(h.binary("rsg_gateway")).resolve())
    units = h.dir / "units"
    units.mkdir()
    text = unit.read_text().replace("/usr/bin/rsg_gateway", gateway_bin)
    (units / "rsg-gateway@.service").write_text(text)
    (units / "rsg-realtime@.service").write_text(text + "\n" + (DEPLOY / "realtime.conf").read_text())
    # --man=no: Documentation= names the installed manual page and guides, which exist once the
    # package is installed (make test-service checks them there), not on a build host.
    for name in ("rsg-gateway@robot1.service", "rsg-realtime@robot1.service"):
        verify = subprocess.run([analyze, "verify", "--man=no", str(units / name)], capture_output=True, text=True,
                                timeout=60)
        check(verify.returncode == 0 and not (verify.stdout + verify.stderr).strip(),
              f"systemd-analyze verify {name} (exit {verify.returncode}):\n{verify.stdout}{verify.stderr}")

    security = subprocess.run([analyze, "security", "--offline=yes", "--no-pager", str(units / "rsg-gateway@robot1.service")],
                              capture_output=True, text=True, timeout=60)
    (h.dir / "security.txt").write_text(security.stdout + security.stderr)
    match = re.search(r"Overall exposure level for \S+: (\d+\.\d+) (\S+)", security.stdout + security.stderr)
    check(match is not None, f"no exposure level in systemd-analyze security's output:\n{security.stdout}{security.stderr}")
    exposure = float(match.group(1))
    print(f"systemd-analyze security: {exposure} {match.group(2)}")
    check(exposure <= MAX_EXPOSURE, f"exposure {exposure} {match.group(2)} > {MAX_EXPOSURE} (see {h.dir}/security.txt)")

    example = settings(DEPLOY / "robot1.yaml")
    for key in BOUNDED_RECORDER:
        check(any(line.startswith(key) for line in example), f"robot1.yaml's flight recorder lacks {key}")

    # The example configuration, with this test's ports and directories instead of the unit's.
    pcap_dir = h.dir / "pcap"
    pcap_dir.mkdir()
    gateway, stats = h.gateway("gateway", "--config", str(DEPLOY / "robot1.yaml"), "--name", "robot1",
                               "--listen", f"127.0.0.1:{free_udp_port()}", "--metrics", "127.0.0.1:0",
                               "--pcap-dir", str(pcap_dir), "--allow-from", "127.0.0.1")
    wait_for_stats(stats, lambda s: True, "the gateway to run robot1.yaml")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")

    two_robots(h, lines)


def other_writers(metrics):
    """rsg_state_other_writers of the gateway on TCP port `metrics`."""
    _, text = http_get(metrics, "/metrics")
    return value_of(parse_samples(text), "rsg_state_other_writers")


def exec_start(lines, instance, gateway_bin):
    """The unit's ExecStart= for `instance`, with this build's binary."""
    line = next(line for line in lines if line.startswith("ExecStart="))
    return [gateway_bin if word == "/usr/bin/rsg_gateway" else word.replace("%i", instance)
            for word in line[len("ExecStart="):].split()]


def two_robots(h, lines):
    gateway_bin = str(Path(h.binary("rsg_gateway")).resolve())
    example = (DEPLOY / "robot1.yaml").read_text()
    check("partition:" not in "".join(l for l in example.splitlines() if not l.lstrip().startswith("#")),
          "robot1.yaml sets a partition: a copy of it would put robot2 in robot1's")
    etc = h.dir / "etc"
    etc.mkdir()
    for kept_partition in (False, True):
        text = example + ("partition: robot1\n" if kept_partition else "")
        for robot in ("robot1", "robot2"):
            (etc / f"{robot}.yaml").write_text(text)
        # As the unit runs them; the check says what each would use.
        for robot in ("robot1", "robot2"):
            argv = [word.replace("/etc/rsg/", f"{etc}/") for word in exec_start(lines, robot, gateway_bin)]
            check_run = subprocess.run([*argv, "--check-config"], capture_output=True, text=True, timeout=60)
            expected_partition = "robot1" if kept_partition else robot
            for expected in (f"partition '{expected_partition}'", f"stats file: /run/rsg/{robot}/stats.json",
                             f"into /var/lib/rsg/{robot}"):
                check(check_run.returncode == 0 and expected in check_run.stdout,
                      f"{robot}.yaml under the unit: {expected!r} not in {check_run.stdout!r} {check_run.stderr!r}")
        if kept_partition:
            label = "kept partition"
        else:
            label = "copied file"
        # Both running, with this test's ports and directories (what the unit's would be, /run and
        # /var/lib, this test does not write), each fed by a robot of its own.
        running = []
        for robot in ("robot1", "robot2"):
            argv = [word.replace("/etc/rsg/", f"{etc}/") for word in exec_start(lines, robot, gateway_bin)]
            port, metrics = free_udp_port(), free_tcp_port()
            stats = h.dir / f"{robot}-{kept_partition}.stats.json"
            (h.dir / f"pcap-{robot}-{kept_partition}").mkdir()
            process = h.start(f"{robot}-{kept_partition}", [
                *argv, "--domain", str(h.domain), "--listen", f"127.0.0.1:{port}", "--allow-from", "127.0.0.1",
                "--metrics", f"127.0.0.1:{metrics}", "--stats-file", str(stats),
                "--pcap-dir", str(h.dir / f"pcap-{robot}-{kept_partition}")])
            sim = h.start(f"sim-{robot}-{kept_partition}", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}",
                                                            "--rate", "200", "--duration", "60"])
            running.append((robot, process, sim, stats, metrics))
        for robot, process, sim, stats, metrics in running:
            wait_for_stats(stats, lambda s: s["link_up"], f"{robot}'s link ({label})")
        if kept_partition:
            for robot, process, sim, stats, metrics in running:
                wait_for(lambda: other_writers(metrics) == 1,
                         f"the control: {robot} to see the other robot's writer in partition robot1")
        else:
            # Discovery has had the time the control needs to see the other writer (both linked up,
            # the first gateway's writer announced before the second started).
            wait_for_stats(running[1][3], lambda s: s["frames_published"] > 400, "robot2 to stream 2 s")
            for robot, process, sim, stats, metrics in running:
                check(other_writers(metrics) == 0, f"{robot} from a copied file sees another robot in its partition")
        for robot, process, sim, stats, metrics in running:
            sim.kill()
            check(h.stop(f"{robot}-{kept_partition}", process) == 0, f"{robot} ({label}) did not exit 0")
        print(f"two robots, {label}: " + ("both say another robot writes in partition robot1" if kept_partition
                                           else "partitions robot1 and robot2, neither sees the other"))


if __name__ == "__main__":
    sys.exit(main("systemd_unit", body))
