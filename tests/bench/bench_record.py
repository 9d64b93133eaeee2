"""Recorder benchmark: rsg_sim (full 2137-byte frames) -> rsg_gateway -> rsg_record for a while,
then the recorder's CPU (from /proc, over the steady part of the run), what it dropped, and the
compression ratio of the file it wrote.

    bench_record.py BUILD_DIR OUT.json [--seconds 30] [--rate 1000]

The issue's 10-minute run at 1 kHz is `--seconds 600` (not part of make bench: too long).
"""

import argparse
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from test_domain import acquire_domain  # noqa: E402  (the domain pool of ctest -j)


def free_udp_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def cpu_seconds(pid):
    """User + system time of a process so far."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def wait_for(predicate, what, timeout_s=20):
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            sys.exit(f"bench_record: timed out waiting for {what}")
        time.sleep(0.05)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("build")
    parser.add_argument("out")
    parser.add_argument("--seconds", type=float, default=30)
    parser.add_argument("--rate", type=int, default=1000)
    args = parser.parse_args()
    bin_dir = Path(args.build) / "bin"
    work = Path(tempfile.mkdtemp(prefix="rsg_bench_record_"))
    domain = acquire_domain()
    port = free_udp_port()
    children = []
    try:
        stats = work / "gateway.stats.json"
        children.append(subprocess.Popen([bin_dir / "rsg_gateway", "--domain", str(domain), "--listen",
                                          f"127.0.0.1:{port}", "--stats-file", stats],
                                         stdout=subprocess.DEVNULL, stderr=open(work / "gateway.err", "wb")))
        recording = work / "bench.mcap"
        recorder_err = work / "record.err"
        recorder = subprocess.Popen([bin_dir / "rsg_record", "--domain", str(domain), "--out", recording],
                                    stdout=subprocess.DEVNULL, stderr=open(recorder_err, "wb"))
        children.append(recorder)

        def matched():
            try:
                return json.loads(stats.read_text())["state_readers"] >= 1
            except (FileNotFoundError, json.JSONDecodeError, KeyError):
                return False

        wait_for(matched, "the recorder to match the gateway")
        count = int(args.seconds * args.rate)
        sim = subprocess.Popen([bin_dir / "rsg_sim", "--to", f"127.0.0.1:{port}", "--rate", str(args.rate),
                                "--count", str(count)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        children.append(sim)
        # The steady part: from 2 s in (discovery and start-up done) to 1 s before the end.
        warmup = min(2.0, args.seconds / 4)
        time.sleep(warmup)
        cpu0, wall0 = cpu_seconds(recorder.pid), time.monotonic()
        time.sleep(max(0.5, args.seconds - warmup - 1))
        cpu1, wall1 = cpu_seconds(recorder.pid), time.monotonic()
        sim.wait(timeout=args.seconds + 30)
        time.sleep(1.0)  # the last samples reach the recorder
        recorder.send_signal(signal.SIGTERM)
        status = recorder.wait(timeout=30)
        err = recorder_err.read_text()
        summary = re.search(r"(\d+) messages in (\d+) chunks.* (\d+) bytes; compression ratio ([\d.]+); "
                            r"received (\d+) states, (\d+) statuses; dropped (\d+) \(sequence gaps\), (\d+) \(lost in DDS\)", err)
        if status != 0 or not summary:
            sys.exit(f"bench_record: rsg_record exited {status}: {err}")
        messages, chunks, file_bytes, ratio, states, statuses, gaps, lost = summary.groups()
        cpu_model = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                          if line.startswith("model name")), "unknown")
        result = {
            "rate_hz": args.rate, "seconds": args.seconds, "frames_sent": count,
            "messages": int(messages), "states": int(states), "statuses": int(statuses), "chunks": int(chunks), "file_bytes": int(file_bytes),
            "compression_ratio": float(ratio), "dropped_sequence_gaps": int(gaps), "lost_in_dds": int(lost),
            "recorder_cpu_percent": round(100 * (cpu1 - cpu0) / (wall1 - wall0), 2),
            "cpu": cpu_model, "cores": os.cpu_count(),
        }
        Path(args.out).write_text(json.dumps(result, indent=2) + "\n")
        print(json.dumps(result))
    finally:
        for child in children:
            if child.poll() is None:
                child.send_signal(signal.SIGTERM)
                try:
                    child.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    child.kill()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
