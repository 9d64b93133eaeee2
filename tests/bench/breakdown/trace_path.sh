#!/usr/bin/env bash
# Traces the wake-ups and system calls of one floor scenario of rsg_bench_e2e at a low rate (so
# that each frame's chain stands alone) and prints the median time of every step of a frame's
# way from the sender's sendto to the reader's listener (breakdown.py).
#
#   tests/bench/breakdown/trace_path.sh BUILD_DIR SCENARIO [RATE_HZ] [SECONDS] [BENCH ARGS...]
#   SCENARIO: floor_gateway_to_fastdds floor_gateway_to_cyclone floor_relay_fastdds_to_fastdds ...
#
# Needs root (perf record -a of sched and raw_syscalls tracepoints) and tracefs, which it mounts
# at /sys/kernel/tracing when absent.
set -euo pipefail
build=${1:?usage: trace_path.sh BUILD_DIR SCENARIO [RATE_HZ] [SECONDS]}
scenario=${2:?usage}
rate=${3:-200}
seconds=${4:-4}
here=$(cd "$(dirname "$0")" && pwd)
command -v perf >/dev/null || { echo "trace_path.sh: perf is missing (apt-get install linux-perf)" >&2; exit 1; }
[[ -e /sys/kernel/tracing/events ]] || mount -t tracefs nodev /sys/kernel/tracing
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

"$build/tests/bin/rsg_bench_e2e" --scenario "$scenario" --rate "$rate" --warmup 2 --duration "$seconds" \
  --out "$work/result.json" "${@:5}" > "$work/bench.log" 2>&1 &
bench=$!
sleep 1.5  # discovery; warm-up frames are flowing by the time the trace starts
children=$(cat /proc/$bench/task/*/children 2>/dev/null | tr ' ' '\n' | grep . | tr '\n' ',' | sed 's/,$//')
perf record -q -a -o "$work/perf.data" \
  -e sched:sched_switch -e sched:sched_wakeup -e raw_syscalls:sys_enter -e raw_syscalls:sys_exit \
  -- sleep "$seconds" 2>/dev/null
wait $bench
perf script -i "$work/perf.data" -F comm,pid,tid,cpu,time,event,trace 2>/dev/null > "$work/trace.txt"
python3 "$here/breakdown.py" "$work/trace.txt" --sender "$bench" --children "$children" \
  --scenario "$scenario ${*:5}" --result "$work/result.json"
