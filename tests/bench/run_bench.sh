#!/usr/bin/env bash
# Runs the benchmark suites of a build, keeps each suite's Google Benchmark JSON in
# BUILD_DIR/bench/<suite>.json and prints them as markdown tables (bench_table.py).
#
#   tests/bench/run_bench.sh BUILD_DIR [SUITE...]      (default: every suite)
#   BENCH_REPETITIONS=5    repetitions per benchmark; the tables show their median
#
# A suite is a function run_<suite> that writes $out/<suite>.json, plus its name in SUITES. The
# end-to-end DDS benchmark goes in as a second suite next to `wire`.
set -euo pipefail

SUITES=(wire)

here=$(cd "$(dirname "$0")" && pwd)
usage() { echo "usage: $0 BUILD_DIR [${SUITES[*]}]" >&2; exit 2; }
[[ $# -ge 1 ]] || usage
build=$1
shift
selected=("${@:-${SUITES[@]}}")
repetitions=${BENCH_REPETITIONS:-5}
out=$build/bench
mkdir -p "$out"

# Options every Google Benchmark suite shares: repetitions summarised by their aggregates.
gbench_options() {
  echo --benchmark_repetitions="$repetitions" --benchmark_report_aggregates_only=true \
    --benchmark_out="$out/$1.json" --benchmark_out_format=json
}

run_wire() {
  # shellcheck disable=SC2046  # word splitting of the options is intended
  "$build/bin/rsg_bench_wire" $(gbench_options wire)
}

for suite in "${selected[@]}"; do
  declare -F "run_$suite" >/dev/null || { echo "$0: unknown suite '$suite'" >&2; usage; }
  echo "== $suite"
  "run_$suite"
done
echo
for suite in "${selected[@]}"; do
  python3 "$here/bench_table.py" "$out/$suite.json"
done
