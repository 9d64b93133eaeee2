"""deploy/systemd: `systemd-analyze verify` accepts rsg-gateway@.service (alone and with the
realtime.conf drop-in) with no warning, `systemd-analyze security` rates it OK (exposure at most
2.0; the figure is in docs/service.md), it keeps the promises docs/service.md makes (Type=notify,
a watchdog, restarts with a limit and none after a configuration error, a dynamic user with the
group `rsg`, a read-only system, the installed documentation), and the real rsg_gateway
runs the example configuration robot1.yaml. Fails (never skips) without systemd-analyze."""

import re
import shutil
import subprocess
import sys
from pathlib import Path

from harness import TestFailure, check, free_udp_port, main, wait_for_stats  # noqa: E402

DEPLOY = Path(__file__).resolve().parents[2] / "deploy" / "systemd"
MAX_EXPOSURE = 2.0
PROMISES = ["Type=notify", "NotifyAccess=main", "WatchdogSec=", "Restart=on-failure", "StartLimitBurst=",
            "RestartPreventExitStatus=2", "DynamicUser=yes", "Group=rsg", "Documentation=man:rsg_gateway(1)",
            "RuntimeDirectory=rsg/%i", "ProtectSystem=strict", "NoNewPrivileges=yes",
            "ExecStart=/usr/bin/rsg_gateway --config /etc/rsg/%i.yaml --name %i",
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


if __name__ == "__main__":
    sys.exit(main("systemd_unit", body))
