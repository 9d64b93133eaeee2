#!/usr/bin/env bash
# Runs every fuzzer listed in BUILD_DIR/fuzz/fuzzers.txt (written by tests/fuzz/CMakeLists.txt) for
# $FUZZ_SECONDS each, FUZZ_JOBS of them at a time (default: one per core), prints executions and
# coverage per fuzzer, and fails if any of them crashed.
#
#   FUZZ_SECONDS=600 tests/fuzz/run_fuzzers.sh build-fuzz
#
# Per fuzzer, under BUILD_DIR/fuzz/: corpus/<name> (grows from run to run; the generated seeds in
# seeds/<name> stay pristine), logs/<name>.log, and artifacts/<name>-crash-* for a failing input.
set -euo pipefail

usage() { echo "usage: FUZZ_SECONDS=N $0 BUILD_DIR" >&2; exit 2; }
[[ $# -eq 1 ]] || usage
build=$1
seconds=${FUZZ_SECONDS:-30}
manifest=$build/fuzz/fuzzers.txt
[[ -f $manifest ]] || { echo "$0: no $manifest; configure $build with -DRSG_FUZZ=ON and build it" >&2; exit 2; }

work=$build/fuzz
mkdir -p "$work/corpus" "$work/logs" "$work/artifacts"
# FUZZ_JOBS fuzzers at a time (default: every core): each is one busy process.
jobs=${FUZZ_JOBS:-$(nproc)}

# One fuzzer; its report goes to logs/<name>.report, its summary row to logs/<name>.row.
fuzz_one() {
  local name=$1 seed_dirs=$2
  local binary=$build/tests/bin/$name log=$work/logs/$name.log corpus=$work/corpus/$name
  local seeds=() status=0 dir last runs cov ft corp
  mkdir -p "$corpus"
  for dir in $seed_dirs; do [[ -d $dir ]] && seeds+=("$dir"); done
  {
    echo "== $name: ${seconds}s, seeds from ${seeds[*]:-(none)}"
    "$binary" -max_total_time="$seconds" -print_final_stats=1 -artifact_prefix="$work/artifacts/$name-" \
      "$corpus" "${seeds[@]}" >"$log" 2>&1 || status=$?
    # libFuzzer's last status line ("#N  DONE  cov: C ft: F corp: ...") and its final stats.
    last=$(grep -E '^#[0-9]+' "$log" | tail -n 1 || true)
    runs=$(sed -nE 's/^stat::number_of_executed_units: *([0-9]+).*/\1/p' "$log" | tail -n 1)
    cov=$(sed -nE 's/.* cov: ([0-9]+).*/\1/p' <<<"$last")
    ft=$(sed -nE 's/.* ft: ([0-9]+).*/\1/p' <<<"$last")
    corp=$(sed -nE 's/.* corp: ([0-9]+\/[0-9]+[a-zA-Z]*).*/\1/p' <<<"$last")
    echo "   $last"
    if [[ $status -ne 0 ]]; then
      echo "   FAILED (exit $status); the end of $log:"
      tail -n 40 "$log" | sed 's/^/   | /'
      echo "| $name | ${runs:-?} | ${cov:-?} | ${ft:-?} | ${corp:-?} | **crash** (exit $status) |" >"$work/logs/$name.row"
    else
      echo "| $name | ${runs:-?} | ${cov:-?} | ${ft:-?} | ${corp:-?} | ok |" >"$work/logs/$name.row"
    fi
  } >"$work/logs/$name.report"
}

names=()
while read -r name seed_dirs; do
  [[ -n $name ]] || continue
  names+=("$name")
  rm -f "$work/logs/$name.row"
  while (($(jobs -pr | wc -l) >= jobs)); do wait -n || true; done
  fuzz_one "$name" "$seed_dirs" &
done <"$manifest"
wait

failed=0
summary=()
for name in "${names[@]}"; do
  cat "$work/logs/$name.report"
  if [[ -f $work/logs/$name.row ]]; then
    summary+=("$(cat "$work/logs/$name.row")")
    grep -q '| ok |$' "$work/logs/$name.row" || failed=1
  else
    failed=1
    summary+=("| $name | ? | ? | ? | ? | **crash** (no report) |")
  fi
done

echo
echo "| fuzzer | executions | cov | ft | corpus | result |"
echo "|---|---:|---:|---:|---|---|"
printf '%s\n' "${summary[@]}"
exit $failed
