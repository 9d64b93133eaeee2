"""deploy/prometheus/rsg-alerts.yml: `promtool check rules` accepts it and `promtool test rules`
passes its own tests (rsg-alerts.test.yml: each alert fires on the series it is for, after its
`for:`, with the gateway's labels and its text, and stays quiet on a healthy gateway's). That the
rules name only metrics the gateway exports is integration.grafana_dashboard's part. Fails (never
skips) without promtool."""

import shutil
import subprocess
import sys
from pathlib import Path

from harness import TestFailure, check, main  # noqa: E402

RULES = Path(__file__).resolve().parents[2] / "deploy" / "prometheus"


def body(h):
    promtool = shutil.which("promtool")
    if promtool is None:
        raise TestFailure("promtool is not installed: apt-get install prometheus (docker/packages/test.txt)")
    for command in (["check", "rules", "rsg-alerts.yml"], ["test", "rules", "rsg-alerts.test.yml"]):
        run = subprocess.run([promtool, *command], cwd=RULES, capture_output=True, text=True, timeout=60)
        check(run.returncode == 0, f"promtool {' '.join(command)} (exit {run.returncode}):\n{run.stdout}{run.stderr}")
        print(f"promtool {' '.join(command)}: {run.stdout.strip().splitlines()[-1]}")


if __name__ == "__main__":
    sys.exit(main("alert_rules", body))
