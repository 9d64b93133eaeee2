#!/usr/bin/env bash
# Thread placement and priorities of every thread, Fast DDS's own included, for the gateway_udp
# scenario: Fast DDS 2.9 has no setting for its threads' affinity or priority, so they are set from
# outside once the gateway is up (taskset -a / chrt -a act on every thread of a process; threads
# started later inherit them). Modes, run alternately ROUNDS times each (runs next to each other see
# the same load):
#
#   free        the scheduler places every thread (as deployed)
#   split       the gateway's threads on CPU 0; the bench's (robot sender, DDS reader) on CPU 1
#   fifo        every thread of the gateway and of the bench SCHED_FIFO 50, placed freely
#   split_fifo  both
#
#   tests/bench/breakdown/placement.sh BUILD_DIR [ROUNDS] [SECONDS]     (needs root for chrt)
#
# Prints every run and the medians of p50/p99 and of the gateway's CPU per mode.
set -euo pipefail
build=${1:?usage: placement.sh BUILD_DIR [ROUNDS] [SECONDS]}
rounds=${2:-3}
seconds=${3:-8}
modes=(free split fifo split_fifo)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Applies a mode to the bench and, once it has started it, to its gateway. The warm-up (4 s) is
# not measured, so the settings are in place before the first measured frame.
apply() {
  local mode=$1 bench=$2 gateway=
  for _ in $(seq 100); do
    gateway=$(pgrep -P "$bench" -x rsg_gateway || true)
    [[ -n $gateway ]] && break
    sleep 0.02
  done
  [[ -n $gateway ]] || { echo "placement.sh: no gateway under $bench" >&2; return 1; }
  sleep 0.5  # Fast DDS starts its threads while the participant comes up
  case $mode in
    split | split_fifo)
      taskset -a -p -c 0 "$gateway" >/dev/null
      taskset -a -p -c 1 "$bench" >/dev/null
      ;;
  esac
  case $mode in
    fifo | split_fifo)
      chrt -a -f -p 50 "$gateway"
      chrt -a -f -p 50 "$bench"
      ;;
  esac
}

for round in $(seq "$rounds"); do
  for mode in "${modes[@]}"; do
    "$build/tests/bin/rsg_bench_e2e" --scenario gateway_udp --duration "$seconds" --warmup 4 \
      --out "$work/$mode.$round.json" >/dev/null 2>&1 &
    bench=$!
    apply "$mode" "$bench" || true
    wait "$bench" || echo "placement.sh: $mode run $round failed" >&2
  done
done

python3 - "$work" "$rounds" "${modes[@]}" <<'PY'
import json, statistics, sys
from pathlib import Path
work, rounds, modes = Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3:]
base = None
for mode in modes:
    runs = [json.loads(f.read_text()) for f in sorted(work.glob(f"{mode}.*.json"))]
    if not runs:
        print(f"{mode:10} no run")
        continue
    p50, p99 = [r["p50_us"] for r in runs], [r["p99_us"] for r in runs]
    cpu = [r["gateway"]["cpu_percent"] for r in runs if "gateway" in r]
    median = (statistics.median(p50), statistics.median(p99))
    base = base or median
    print(f"{mode:10} p50 {' '.join(f'{v:.1f}' for v in p50)}  p99 {' '.join(f'{v:.1f}' for v in p99)}  "
          f"gateway CPU {' '.join(f'{v:.1f}' for v in cpu)} %  | median p50 {median[0]:.1f} "
          f"({median[0] / base[0]:.2f} x free), p99 {median[1]:.1f} ({median[1] / base[1]:.2f} x free)")
PY
