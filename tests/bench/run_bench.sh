#!/usr/bin/env bash
# Runs the benchmark suites of a build into BUILD_DIR/bench/ and prints their tables.
#
#   tests/bench/run_bench.sh BUILD_DIR [SUITE...]      (default: every suite)
#
#   wire  the codec (rsg_bench_wire, Google Benchmark): bench/wire.json, tables by bench_table.py
#         BENCH_REPETITIONS=5    repetitions per benchmark; the tables show their median
#   e2e   frames through a running rsg_gateway to a DDS reader, and baselines (rsg_bench_e2e):
#         bench/results.json, results.md, latency_cdf.png (e2e_report.py), raw runs in bench/e2e/.
#         About 11.5 minutes: 30 s per latency run, 10 s per max-rate step (UDP, then data-sharing),
#         and the 5-minute RSS soak running alongside them.
#         RSG_BENCH_FULL=1   120 s per latency run, 30 s per max-rate step, the soak on its own
#                            afterwards (about 25 minutes, quieter numbers)
#         RSG_BENCH_E2E_SECONDS, RSG_BENCH_E2E_STEP_SECONDS, RSG_BENCH_E2E_SOAK_SECONDS override
#                            those durations (e.g. a quick try of the suite)
#   record  rsg_record at 1 kHz full frames for 30 s (bench_record.py): the recorder's CPU, what it
#         dropped, and the file's compression ratio: bench/record.json.
#         RSG_BENCH_RECORD_SECONDS overrides the 30 s (600 for the issue's 10-minute run)
#   scale N robots (robot + gateway each) and M remote readers of one gateway, N, M = 1, 4, 8, 16, in
#         network namespaces (tests/bench/scale.py; needs root): CPU, RSS, first sample and p50/p99
#         latency (robot's send to remote reader, rsg_bench_scale_probe) per point: bench/scale/
#         (scale.json, scale.md, PNG plots), with the Discovery Server. About 3 minutes, plus the
#         wait for an idle host before each point (up to 2 minutes each).
#         RSG_BENCH_SCALE_SECONDS   measuring window per point (default 8)
#         RSG_BENCH_SCALE_SERIES    scale.py --series (default robots,readers; add readers_multicast
#                                   for M readers of rsg_participant_multicast: four more points)
#         What the gateways send is forwarded and delivered on a kernel thread (--receive-off-sender),
#         as a NIC leaves that work to the readers' machines; RSG_BENCH_SCALE_SENDER_PAYS=1 keeps the
#         plain veth, which runs it inside the gateway's sendmsg (the committed runs before 2026-11-23 21:30)
#   late_join  a reader started next to a running gateway, 100 times, with rsg's participant profile
#         and with Fast DDS's default announcement period (late_join.py): time to the first sample,
#         bench/late_join/ (late_join.json, late_join.md). About 1.5 minutes.
#         RSG_BENCH_LATE_JOIN_STARTS   starts per profile (default 100)
#   readers  what 0, 1, 4 and 16 readers of each kind (plain, rsg view, ad-hoc groups, ROS 2 content
#         filter, ROS 2 plain) cost rsg_gateway at 1 kHz (tests/bench/readers/readers.py): gateway and
#         readers' CPU, frames published, largest ingress delay, link-down reports:
#         bench/readers/readers_fastdds2.9.json. About 4 minutes.
#         RSG_BENCH_READERS_SECONDS   measuring window per point (default 8)
#   churn  readers of every kind joining and leaving a 1 kHz gateway (tests/dds/test_views_churn.py,
#         views and the plain control, 3 runs each) with cyclictest alongside: the gateway's largest
#         ingress delay next to the host's own largest real-time wake-up latency in the same run
#         (tests/bench/readers/churn.py): bench/churn/churn_fastdds2.9.json and .md. About 9 minutes.
#         RSG_BENCH_CHURN_RUNS        runs per kind (default 3)
#         RSG_BENCH_CHURN_GATEWAY_ARGS  the gateway's flags (default --rt-priority 30; add --cpu N on
#                                     a host with an isolated core)
#   dumps  what a flight-recorder dump (SIGUSR1, 10 s ring) costs the stream at 1 kHz: the gateway's
#         largest ingress delay in 2.5 s windows with a dump and without (tests/bench/dump_stall.py):
#         bench/dumps/dump_stall.json. About 1.5 minutes.
#   metrics  what Prometheus scraping costs rsg_gateway at 1 kHz (tests/bench/metrics_cost.py): the
#         gateway's CPU with --metrics scraped once a second, side by side with metrics off, and the
#         cost of one scrape (from 100 scrapes a second), alternating, over several rounds:
#         bench/metrics/metrics_cost.json. About 5 minutes.
#         RSG_BENCH_METRICS_ROUNDS    rounds (default 4), RSG_BENCH_METRICS_SECONDS window (default 20)
#   ros2_rate  what a plain rclpy subscriber (default reliable QoS) on ROS 2 Jazzy
#         receives from rsg_gateway --ros2 fed at 1 kHz, next to a plain rclpy publisher at 1 kHz of
#         the same distribution (the floor): rate, lost, inter-arrival p50/p99/max, the
#         subscriber's CPU (tests/bench/ros2_rate/ros2_rate.py, make deps' ROS 2 environment):
#         bench/ros2_rate/ (ros2_rate.json, ros2_rate.md). About 5 minutes.
#         RSG_BENCH_ROS2_RATE_SECONDS  measuring window per run (default 60)
#         RSG_BENCH_ROS2_RATE_DISTROS  distributions (default jazzy; Kilted, measured before its retirement, in docs/benchmarks/ros2_rate/)
#
# A suite is a function run_<suite> that writes its results under $out and a function
# report_<suite> that prints them, plus its name in SUITES.
set -euo pipefail

SUITES=(wire e2e record scale late_join readers churn dumps metrics ros2_rate)

here=$(cd "$(dirname "$0")" && pwd)
# The Python benches import tests/support's helpers by name: that folder on PYTHONPATH, as ctest's
# tests/support/python.py puts it.
export PYTHONPATH=$here/../support${PYTHONPATH:+:$PYTHONPATH}
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
  "$build/tests/bin/rsg_bench_wire" $(gbench_options wire)
}
report_wire() { python3 "$here/bench_table.py" "$out/wire.json"; }

# Latency runs in the order the report compares them: baselines next to the gateway they judge.
e2e_soak_pid=
E2E_LATENCY_SCENARIOS=(baseline_udp_oneway embedded_callback baseline_fastdds gateway_udp gateway_udp_ros2_standard
                       floor_relay_fastdds_to_fastdds floor_relay_cyclone_to_fastdds
                       floor_relay_cyclone_to_cyclone floor_relay_fastdds_to_cyclone floor_gateway_to_cyclone
                       baseline_fastdds_shm gateway_shm
                       baseline_fastdds_datasharing gateway_datasharing
                       cyclone_ddsperf)

run_e2e() {
  local bench=$build/tests/bin/rsg_bench_e2e runs=$out/e2e
  local seconds=30 step_seconds=10 soak_seconds=300 soak_concurrent=true
  if [[ ${RSG_BENCH_FULL:-0} == 1 ]]; then
    seconds=120 step_seconds=30 soak_concurrent=false
  fi
  seconds=${RSG_BENCH_E2E_SECONDS:-$seconds}
  step_seconds=${RSG_BENCH_E2E_STEP_SECONDS:-$step_seconds}
  soak_seconds=${RSG_BENCH_E2E_SOAK_SECONDS:-$soak_seconds}
  rm -rf "$runs" && mkdir -p "$runs"
  local commit
  # RSG_BENCH_COMMIT: where git cannot tell (the Fast DDS 3 chroot has no git).
  commit=${RSG_BENCH_COMMIT:-$(git -C "$here" describe --always --dirty 2>/dev/null || echo unknown)}
  printf '{"latency_run_s": %s, "max_rate_step_s": %s, "soak_s": %s, "soak_concurrent": %s, "full": %s, "commit": "%s"}\n' \
    "$seconds" "$step_seconds" "$soak_seconds" "$soak_concurrent" "${RSG_BENCH_FULL:-0}" "$commit" >"$runs/settings.json"

  # Each rsg_bench_e2e run stops its own children; the soak is ours to stop if we are stopped.
  trap '[[ -n $e2e_soak_pid ]] && kill "$e2e_soak_pid" 2>/dev/null; fastdds shm clean >/dev/null 2>&1 || true' EXIT
  local soak=("$bench" --scenario soak --duration "$soak_seconds" --out "$runs/soak.json")
  # The 5-minute RSS soak is one more 1 kHz stream; by default it runs alongside the other runs
  # (every run, baselines included, shares that load) so that the suite fits in 10 minutes.
  if $soak_concurrent; then
    echo "-- soak (${soak_seconds} s, in the background)"
    "${soak[@]}" &
    e2e_soak_pid=$!
  fi
  for scenario in "${E2E_LATENCY_SCENARIOS[@]}"; do
    echo "-- $scenario (${seconds} s, load average $(cut -d' ' -f1-3 /proc/loadavg))"
    "$bench" --scenario "$scenario" --duration "$seconds" --out "$runs/$scenario.json" --cdf "$runs/$scenario.cdf"
  done
  echo "-- max_rate (${step_seconds} s per step, UDP, then data-sharing)"
  "$bench" --scenario max_rate --duration "$step_seconds" --out "$runs/max_rate.json"
  "$bench" --scenario max_rate --transport datasharing --duration "$step_seconds" \
    --out "$runs/max_rate_datasharing.json"
  if $soak_concurrent; then
    echo "-- waiting for the soak"
    wait "$e2e_soak_pid"
    e2e_soak_pid=
  else
    echo "-- soak (${soak_seconds} s)"
    "${soak[@]}"
  fi
  fastdds shm clean >/dev/null 2>&1 || true
  python3 "$here/e2e_report.py" "$runs" "$out" >/dev/null
}
report_e2e() { cat "$out/results.md"; }

run_record() {
  python3 "$here/bench_record.py" "$build" "$out/record.json" --seconds "${RSG_BENCH_RECORD_SECONDS:-30}"
}
report_record() {
  python3 - "$out/record.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
print(f"rsg_record at {r['rate_hz']} Hz, full frames, {r['seconds']:.0f} s ({r['cpu']}, {r['cores']} cores)")
print()
print("| recorder CPU | frames sent | states recorded | dropped (gaps / DDS lost) | file | compression ratio |")
print("|---:|---:|---:|---:|---:|---:|")
print(f"| {r['recorder_cpu_percent']} % of a core | {r['frames_sent']} | {r['states']} "
      f"| {r['dropped_sequence_gaps']} / {r['lost_in_dds']} "
      f"| {r['file_bytes'] / 1e6:.1f} MB | {r['compression_ratio']:.2f} |")
PY
}
run_scale() {
  local where=(--receive-off-sender)
  [[ ${RSG_BENCH_SCALE_SENDER_PAYS:-0} == 1 ]] && where=()
  python3 "$here/scale.py" --bin "$build/bin" --test-bin "$build/tests/bin" --out "$out/scale" \
    --seconds "${RSG_BENCH_SCALE_SECONDS:-8}" \
    --series "${RSG_BENCH_SCALE_SERIES:-robots,readers}" --discovery-server "${where[@]}" >/dev/null
}
report_scale() { cat "$out/scale/scale.md"; }

run_late_join() {
  python3 "$here/late_join.py" --bin "$build/bin" --out "$out/late_join" --starts "${RSG_BENCH_LATE_JOIN_STARTS:-100}" >/dev/null
}
report_late_join() { cat "$out/late_join/late_join.md"; }

run_readers() {
  python3 "$here/readers/readers.py" --bin "$build/bin" --test-bin "$build/tests/bin" --out "$out/readers" \
    --seconds "${RSG_BENCH_READERS_SECONDS:-8}" > "$out/readers.txt"
}
report_readers() { sed -n '/^###/,$p' "$out/readers.txt"; }

run_churn() {
  RSG_DEPS_DIR=$(sed -n 's/^RSG_DEPS_DIR:PATH=//p' "$build/CMakeCache.txt") \
    python3 "$here/readers/churn.py" --bin "$build/bin" --out "$out/churn" --runs "${RSG_BENCH_CHURN_RUNS:-3}" \
    --gateway-args "${RSG_BENCH_CHURN_GATEWAY_ARGS:---rt-priority 30}" > "$out/churn.txt"
}
report_churn() { sed -n '/^###/,$p' "$out/churn.txt"; }

run_dumps() { python3 "$here/dump_stall.py" --bin "$build/bin" --out "$out/dumps" > "$out/dumps.txt"; }
report_dumps() { sed -n '/^###/,$p' "$out/dumps.txt"; }

run_metrics() {
  python3 "$here/metrics_cost.py" --bin "$build/bin" --out "$out/metrics" --rounds "${RSG_BENCH_METRICS_ROUNDS:-4}" \
    --seconds "${RSG_BENCH_METRICS_SECONDS:-20}" > "$out/metrics.txt"
}
report_metrics() { sed -n '/^###/,$p' "$out/metrics.txt"; }

run_ros2_rate() {
  RSG_DEPS_DIR=$(sed -n 's/^RSG_DEPS_DIR:PATH=//p' "$build/CMakeCache.txt") \
    python3 "$here/ros2_rate/ros2_rate.py" --bin "$build/bin" --out "$out/ros2_rate" \
    --seconds "${RSG_BENCH_ROS2_RATE_SECONDS:-60}" --distros "${RSG_BENCH_ROS2_RATE_DISTROS:-jazzy}" \
    > "$out/ros2_rate.txt"
}
report_ros2_rate() { cat "$out/ros2_rate/ros2_rate.md"; }

for suite in "${selected[@]}"; do
  declare -F "run_$suite" >/dev/null || { echo "$0: unknown suite '$suite'" >&2; usage; }
done
for suite in "${selected[@]}"; do
  echo "== $suite"
  "run_$suite"
done
echo
for suite in "${selected[@]}"; do
  "report_$suite"
done
