"""Random network faults (the simulator's probabilistic mode, seeded): the gateway's sequence
counters equal what was injected.

tests/integration/test_sequence_and_link.py covers faults placed at fixed periods (--X-every),
never adjacent to each other. Here drops, duplicates, reorders and corruptions are drawn at random
per frame (2 % each), so they also land next to each other, in bursts and across packet-number
wraps: the cases a periodic schedule never produces. Two seeded runs: frames carrying `time` (the
tracker orders by time) and frames without it (packet numbers alone).

Pins that, for both, lost = dropped (a corrupted frame is invalid, not also lost), duplicated and reordered equal the simulator's
counts, every datagram and every invalid category is counted, and every valid frame is published but,
with time, the reordered ones: a frame whose time goes back is counted out_of_sequence, not published.
"""

import sys

from reliability import check_counters, log, main, run_sim, settled_stats, start_gateway

RATE_HZ = 1000
COUNT = 5000
FAULTS = ["--drop", "0.02", "--duplicate", "0.02", "--reorder", "0.02", "--corrupt", "0.02"]
RUNS = {"with_time": (["--fields", "q,time"], "11"), "without_time": (["--fields", "q"], "12")}


def body(h):
    for label, (selection, seed) in RUNS.items():
        gateway, stats, port = start_gateway(h, RATE_HZ, label=f"gateway_{label}")
        report, _, _ = run_sim(h, port, RATE_HZ, COUNT, *selection, *FAULTS, "--seed", seed, label=f"sim_{label}")
        log(h, f"{label}: injected dropped {report['dropped']} duplicated {report['duplicated']} "
               f"reordered {report['reordered']} invalid {sum(report['invalid'].values())}")
        late = report["reordered"] if label == "with_time" else 0
        check_counters(settled_stats(stats, report), report, f"stats file ({label})", out_of_sequence=late)
        h.stop(f"gateway_{label}", gateway)


if __name__ == "__main__":
    sys.exit(main("random_faults", body))
