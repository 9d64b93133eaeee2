"""Where a remote reader's cost lands in the gateway's CPU time on the scale suite's bed.

    reader_cost.py --bin BUILD/bin [--points 1,16] [--seconds 6] [--series readers,readers_multicast]

Runs the scale suite's "M remote readers of one gateway" points (tests/bench/scale.py, network
namespaces joined by veth pairs and a bridge; needs root and perf) and samples the gateway with
`perf record -e cpu-clock -g` over each point's window. On a veth pair the kernel delivers a sent
datagram within the sender's system call: the bridge, the reader host's IP stack (defragmenting the
two fragments of a 2.2 kB sample) and the wake-up of the reader run as network receive softirq work
(`net_rx_action`) on the gateway's own thread. With a NIC that work happens on the reader's
machine. So the gateway's CPU splits into the receive-side work the bed adds (samples under
`net_rx_action`) and the rest: what the gateway would cost on a real network. (`scale.py
--receive-off-sender` measures the rest directly, with that work moved to a kernel thread; this
script keeps the plain veth on purpose, to show the split.)

Prints a table per series and the per-reader slopes of both parts.
"""

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from netbed import NetBed  # noqa: E402
from scale import SERIES, Point, fit_slope  # noqa: E402

RECEIVE_SIDE = "net_rx_action"


class ProfiledPoint(Point):
    def window(self, gateways):
        self.perf_data = Path(self.dir) / "gateway.perf.data"
        subprocess.run(["perf", "record", "-q", "-e", "cpu-clock", "-F", "2000", "-g",
                        "-p", ",".join(str(g.pid) for g in gateways), "-o", str(self.perf_data),
                        "--", "sleep", str(self.args.seconds)],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def receive_side_fraction(self):
        """Share of the gateway's samples with net_rx_action on the stack (inclusive)."""
        report = subprocess.run(["perf", "report", "-i", str(self.perf_data), "--children", "--stdio",
                                 "--sort", "sym", "-g", "none", "--percent-limit", "0"],
                                capture_output=True, text=True, check=True).stdout
        for line in report.splitlines():
            fields = line.split()
            if len(fields) >= 4 and fields[-1] == RECEIVE_SIDE:
                return float(fields[0].rstrip("%")) / 100
        return 0.0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--bin", required=True)
    parser.add_argument("--test-bin", help="directory of the bench's helpers (default: BIN/../tests/bin, the build "
                                           "tree's: CONTRIBUTING.md, \"Build tree\")")
    parser.add_argument("--points", default="1,16")
    parser.add_argument("--seconds", type=float, default=6.0)
    parser.add_argument("--warmup", type=float, default=2.0)
    parser.add_argument("--series", default="readers,readers_multicast")
    args = parser.parse_args()
    args.discovery_server = False
    points = [int(p) for p in args.points.split(",")]
    with NetBed() as bed:
        for series in args.series.split(","):
            rows = []
            for readers in points:
                with tempfile.TemporaryDirectory(prefix="rsg_reader_cost_") as scratch:
                    point = ProfiledPoint(args, bed, scratch, robots=1, readers=readers,
                                          participant_profile=SERIES[series][3])
                    row = point.measure()
                    fraction = point.receive_side_fraction()
                total = row["gateway_cpu_pct_total"]
                rows.append((readers, total, total * fraction, total * (1 - fraction), row["rate_hz_min"]))
            print(f"\n{series} (readers of {SERIES[series][3]}), gateway CPU % of a core over {args.seconds:.0f} s:\n")
            print("| M | gateway CPU % | in net_rx_action (the bed's receive side) | the rest | min rate Hz |")
            print("|---:|---:|---:|---:|---:|")
            for m, total, rx, rest, rate in rows:
                print(f"| {m} | {total:.1f} | {rx:.1f} | {rest:.1f} | {rate:.0f} |")
            if len(rows) >= 2:
                xs = [r[0] for r in rows]
                print(f"\nper added reader: {fit_slope(xs, [r[1] for r in rows]):.2f} % in all, "
                      f"{fit_slope(xs, [r[2] for r in rows]):.2f} % receive side, "
                      f"{fit_slope(xs, [r[3] for r in rows]):.2f} % the rest")
    return 0


if __name__ == "__main__":
    sys.exit(main())
