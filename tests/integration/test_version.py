"""rsg_gateway --version prints "rsg_gateway VERSION (Fast DDS X.Y.Z)" on stdout and exits 0 without
starting anything; VERSION is CMakeLists.txt's project version, and both match what the metrics'
rsg_build_info says."""

import re
import subprocess
import sys
from pathlib import Path

from harness import check, main
from metrics_support import http_get, parse_samples, start_gateway

ROOT = Path(__file__).resolve().parents[2]


def body(h):
    project = re.search(r"project\(rsg VERSION (\S+)", (ROOT / "CMakeLists.txt").read_text()).group(1)
    done = subprocess.run([h.binary("rsg_gateway"), "--version"], capture_output=True, text=True, timeout=30)
    check(done.returncode == 0 and not done.stderr, f"--version: exit {done.returncode}, stderr {done.stderr!r}")
    match = re.fullmatch(r"rsg_gateway (\S+) \(Fast DDS (\d+\.\d+\.\d+)\)\n", done.stdout)
    check(match is not None, f"--version printed {done.stdout!r}")
    check(match.group(1) == project, f"--version says {match.group(1)}, CMakeLists.txt {project}")

    gateway, _, _, metrics = start_gateway(h, "gateway")
    info = [labels for name, labels, _ in parse_samples(http_get(metrics, "/metrics")[1]) if name == "rsg_build_info"]
    # Every series carries the `gateway` label (without --name or --partition: the host's name).
    check(len(info) == 1 and {k: v for k, v in info[0].items() if k != "gateway"} ==
          {"version": project, "fastdds_version": match.group(2)} and info[0].get("gateway"), f"rsg_build_info {info}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("version", body))
