"""What a flight-recorder dump costs the stream: the gateway's ingress delay while it dumps.

    dump_stall.py --bin BUILD/bin [--rounds 8] [--window 10] --out DIR

A fresh rsg_gateway (`--rt-priority 30` where allowed) with `--pcap-ring WINDOW` takes full frames
from rsg_sim at 1 kHz (SCHED_FIFO where allowed); once the ring is full, `--rounds` times: 2.5 s
without a dump, then SIGUSR1 and 2.5 s with one. For each window the largest `ingress_delay_us`
the stats file reported (arrival at the socket to publication, per 1 s status period). The
windows without a dump are the host's own noise. Writes DIR/dump_stall.json and prints a table.
Timings only: no pass/fail.
"""
import argparse
import json
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "readers"))
from harness import acquire_domain, free_udp_port, read_json  # noqa: E402
from readers import realtime_prefix, terminate  # noqa: E402

WINDOW_S = 2.5


def worst_delay(stats, seconds):
    """The largest per-period ingress delay the stats file shows within `seconds`, in us."""
    worst, end = 0, time.monotonic() + seconds
    while time.monotonic() < end:
        current = read_json(stats)
        if current:
            worst = max(worst, current["ingress_delay_us"])
        time.sleep(0.05)
    return worst


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--bin", required=True, type=Path)
    parser.add_argument("--rounds", type=int, default=8)
    parser.add_argument("--window", type=float, default=10, help="the flight recorder's --pcap-ring, s")
    parser.add_argument("--out", required=True, type=Path)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix="dump_stall_", dir=args.out))
    (work / "dumps").mkdir()
    stats, port = work / "gateway.stats.json", free_udp_port()
    realtime = ["--rt-priority", "30"] if realtime_prefix() else []
    gateway = subprocess.Popen([str(args.bin / "rsg_gateway"), "--listen", f"127.0.0.1:{port}", "--expected-rate",
                                "1000", "--pcap-ring", str(args.window), "--pcap-dir", str(work / "dumps"),
                                "--pcap-min-interval", "0",  # a dump every round, on purpose
                                "--stats-file", str(stats), "--domain", str(acquire_domain()), *realtime],
                               stdout=subprocess.DEVNULL, stderr=open(work / "gateway.err", "w"))
    seconds = args.window + 3 + args.rounds * 2 * (WINDOW_S + 0.5) + 5
    sim = subprocess.Popen([*realtime_prefix(), str(args.bin / "rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate",
                            "1000", "--duration", str(seconds), "--every", "1:all"],
                           stdout=subprocess.DEVNULL, stderr=open(work / "sim.err", "w"))
    try:
        time.sleep(args.window + 3)  # the ring full
        quiet, dumping = [], []
        for _ in range(args.rounds):
            time.sleep(0.5)
            quiet.append(worst_delay(stats, WINDOW_S))
            gateway.send_signal(signal.SIGUSR1)
            dumping.append(worst_delay(stats, WINDOW_S))
    finally:
        terminate(sim)
        terminate(gateway)
    dumps = sorted((work / "dumps").glob("*_signal.pcap"))
    result = {"window_s": args.window, "realtime": bool(realtime), "dump_bytes": [p.stat().st_size for p in dumps],
              "with_dump_us": dumping, "without_dump_us": quiet}
    (args.out / "dump_stall.json").write_text(json.dumps(result, indent=1) + "\n")
    ms = lambda values: ", ".join(f"{v / 1000:.1f}" for v in values)  # noqa: E731
    print(f"### Flight-recorder dumps: the ingress delay while one is taken ({args.window:g} s ring, 1 kHz full "
          f"frames, {len(dumps)} dumps of {dumps and dumps[0].stat().st_size / 1e6:.1f} MB)\n")
    print("| windows of 2.5 s | largest ingress delay per window, ms |\n|---|---|")
    print(f"| with a dump | {ms(dumping)} |\n| without | {ms(quiet)} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
