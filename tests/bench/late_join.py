"""`make bench` late-join suite: how long a consumer started after the gateway waits for its first
sample, with rsg's participant profile and with Fast DDS's default announcement period.

    late_join.py --bin BUILD/bin --out DIR [--starts 100]
    late_join.py --bin BUILD/bin --out DIR --render DIR/late_join.json   (redo the table)

For each participant profile, on loopback with SIMPLE discovery: rsg_sim streams full frames at
1 kHz into rsg_gateway, then rsg_echo --json --count 1 is started --starts times, one after the
other; the time from launching rsg_echo to its first line on stdout is one start. Gateway and
readers use the same profile:

  rsg_participant                the shipped profile: announcements every 0.5 s
  fastdds_default_announcements  the same without leaseAnnouncement: Fast DDS's 3 s

Why the period matters: Fast DDS 2.9.1 sometimes loses the gateway's reply to a late joiner's
first announcement (xml_profiles/rsg.xml says when), and the late joiner then learns of the
gateway only from the gateway's next periodic announcement.

How often the reply is lost varies from run to run (more often on a busy host): compare the two
profiles within one run. Writes DIR/late_join.json and DIR/late_join.md.
"""

import argparse
import json
import math
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PROFILES = ROOT / "xml_profiles"

# rsg_participant without its leaseAnnouncement, loaded after rsg.xml (files load in name order).
DEFAULT_ANNOUNCEMENTS = """<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <profiles>
    <participant profile_name="fastdds_default_announcements">
      <rtps>
        <name>rsg</name>
        <userTransports>
          <transport_id>rsg_udp</transport_id>
        </userTransports>
        <useBuiltinTransports>false</useBuiltinTransports>
      </rtps>
    </participant>
  </profiles>
</dds>
"""

VARIANTS = [("rsg_participant", "rsg's profile: announcements every 0.5 s"),
            ("fastdds_default_announcements", "Fast DDS's default: announcements every 3 s")]


def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def cpu_model():
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "unknown CPU"


def first_line_after(argv, timeout_s):
    """Seconds from launching argv to its first stdout line (None if it printed none in time)."""
    launched = time.monotonic()
    process = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        line = process.stdout.readline()
        elapsed = time.monotonic() - launched
        process.wait(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
    return elapsed if line else None


def measure(args, profiles, profile, domain):
    b = Path(args.bin)
    port = free_udp_port()
    common = ["--domain", str(domain), "--profiles", str(profiles), "--participant-profile", profile]
    gateway = subprocess.Popen([b / "rsg_gateway", "--listen", f"127.0.0.1:{port}", *common],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    sim = subprocess.Popen([b / "rsg_sim", "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", "100000000"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        time.sleep(args.settle)
        times = []
        for _ in range(args.starts):
            waited = first_line_after([b / "rsg_echo", *common, "--json", "--count", "1", "--timeout", "10"], 15)
            times.append(waited if waited is not None else float("inf"))
        return times
    finally:
        for process in (sim, gateway):
            process.send_signal(signal.SIGTERM)
        for process in (sim, gateway):
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                process.kill()


def summary(times):
    ordered = sorted(times)

    def pick(q):  # nearest rank: the smallest value with at least q of the starts at or below it
        return ordered[max(0, math.ceil(q * len(ordered)) - 1)]

    return {"starts": len(times), "p50_s": pick(0.5), "p90_s": pick(0.9), "p99_s": pick(0.99), "max_s": ordered[-1],
            "over_0_5s": sum(1 for t in times if t > 0.5), "over_1s": sum(1 for t in times if t > 1.0),
            "times_s": times}


def render(results):
    lines = [f"# Late joiners: time to the first sample ({results['cpu']}, {results['cores']} cores)", "",
             f"rsg_echo started {results['starts']} times, one after the other, next to a running rsg_gateway "
             "fed at 1 kHz (loopback, SIMPLE discovery); from launching it to its first sample on stdout. "
             "Generated by `tests/bench/late_join.py` (`make bench`, suite `late_join`).", "",
             "| participant profile | p50 s | p90 s | p99 s | max s | starts over 0.5 s | over 1 s |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for name, label in VARIANTS:
        r = results["variants"][name]
        lines.append(f"| `{name}` ({label}) | {r['p50_s']:.2f} | {r['p90_s']:.2f} | {r['p99_s']:.2f} | "
                     f"{r['max_s']:.2f} | {r['over_0_5s']} of {r['starts']} | {r['over_1s']} of {r['starts']} |")
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--bin", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--starts", type=int, default=100)
    parser.add_argument("--settle", type=float, default=1.5, help="seconds between the gateway's start and the first reader")
    parser.add_argument("--render", help="only redo OUT/late_join.md (and the summaries) from this late_join.json")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.render:
        results = json.loads(Path(args.render).read_text())
        for name in results["variants"]:
            results["variants"][name] = summary(results["variants"][name]["times_s"])
        (out / "late_join.json").write_text(json.dumps(results, indent=1) + "\n")
        (out / "late_join.md").write_text(render(results))
        return 0
    domain = os.getpid() % 80 + 140
    results = {"cpu": cpu_model(), "cores": os.cpu_count(), "starts": args.starts, "variants": {}}
    with tempfile.TemporaryDirectory(prefix="rsg_late_join_") as scratch:
        profiles = Path(scratch) / "profiles"
        shutil.copytree(PROFILES, profiles)
        (profiles / "zz_late_join.xml").write_text(DEFAULT_ANNOUNCEMENTS)
        for index, (name, _) in enumerate(VARIANTS):
            results["variants"][name] = summary(measure(args, profiles, name, domain + index))
            print(f"{name}: {json.dumps({k: v for k, v in results['variants'][name].items() if k != 'times_s'})}",
                  file=sys.stderr)
    (out / "late_join.json").write_text(json.dumps(results, indent=1) + "\n")
    (out / "late_join.md").write_text(render(results))
    print(render(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
