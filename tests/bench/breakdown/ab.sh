#!/usr/bin/env bash
# A/B of one option on a shared, noisy machine: runs SCENARIO with the base arguments and with
# the variant's, alternately, ROUNDS times each, and prints every run and the medians of p50/p99
# (and the publisher's CPU). Runs next to each other see the same load; one run alone does not.
#
#   tests/bench/breakdown/ab.sh BUILD_DIR SCENARIO "BASE ARGS" "VARIANT ARGS" [ROUNDS] [SECONDS]
#   tests/bench/breakdown/ab.sh build gateway_udp "" "--writer-profile bench_writer_no_deadline"
set -euo pipefail
build=${1:?usage: ab.sh BUILD_DIR SCENARIO BASE_ARGS VARIANT_ARGS [ROUNDS] [SECONDS]}
scenario=${2:?usage}
base=${3-}
variant=${4-}
rounds=${5:-3}
seconds=${6:-8}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for round in $(seq "$rounds"); do
  for side in base variant; do
    args=$base
    [[ $side == variant ]] && args=$variant
    # shellcheck disable=SC2086  # the argument strings are meant to split
    "$build/bin/rsg_bench_e2e" --scenario "$scenario" --duration "$seconds" --warmup 2 $args \
      --out "$work/$side.$round.json" >/dev/null 2>&1 || echo "ab.sh: $side run $round failed" >&2
  done
done
python3 - "$work" "$rounds" "$base" "$variant" <<'PY'
import json, statistics, sys
from pathlib import Path
work, rounds, base, variant = Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4]
def cpu(run):
    return run.get("gateway", {}).get("cpu_percent", run.get("publisher_cpu_percent", run.get("process_cpu_percent")))
summary = {}
for side, args in (("base", base), ("variant", variant)):
    runs = [json.loads((work / f"{side}.{r}.json").read_text()) for r in range(1, rounds + 1)
            if (work / f"{side}.{r}.json").exists()]
    p50 = [r["p50_us"] for r in runs]
    p99 = [r["p99_us"] for r in runs]
    cpus = [c for c in (cpu(r) for r in runs) if c is not None]
    summary[side] = (statistics.median(p50), statistics.median(p99), statistics.median(cpus) if cpus else None)
    print(f"{side:8} {args or '(defaults)'}: p50 {' '.join(f'{v:.1f}' for v in p50)}  "
          f"p99 {' '.join(f'{v:.1f}' for v in p99)}  cpu {' '.join(f'{v:.1f}' for v in cpus)}")
b, v = summary["base"], summary["variant"]
print(f"median p50 {b[0]:.1f} -> {v[0]:.1f} us ({v[0] / b[0]:.2f} x), p99 {b[1]:.1f} -> {v[1]:.1f} us "
      f"({v[1] / b[1]:.2f} x)" + (f", CPU {b[2]:.1f} -> {v[2]:.1f} %" if b[2] is not None and v[2] is not None else ""))
PY
