#!/usr/bin/env bash
# make bench-fastdds3: make bench's e2e suite on Fast DDS 2.9 (the host's build) and then on 3.x
# (3.6.1, the chroot's build of tools/fastdds3/chroot.sh; the committed runs were 3.1.2's), one right after the other on
# one machine, and the two side by side (tests/bench/compare_fastdds.py); then the readers suite
# (tests/bench/readers/readers.py) with a 2.9 gateway and with a 3.x gateway (the readers run on
# the host in both), and the churn suite (tests/bench/readers/churn.py) with a 3.x gateway. The
# committed runs and what they say: docs/benchmarks/fastdds3/, docs/benchmarks/readers/.
#
#   tests/fastdds3/bench.sh [HOST_BUILD [SUITE...]]   HOST_BUILD: the host's 2.9 build tree (default
#                                                     build); SUITE: e2e, readers, churn (default
#                                                     e2e and readers)
#
# The RSG_BENCH_E2E_* durations of tests/bench/run_bench.sh apply to both runs.
set -euo pipefail
cd "$(dirname "$0")/../.."
# The Python benches import tests/support's helpers by name: that folder on PYTHONPATH, as ctest's
# tests/support/python.py puts it.
export PYTHONPATH=$PWD/tests/support${PYTHONPATH:+:$PYTHONPATH}
host_build=${1:-build}
shift || true
suites=("${@:-e2e readers}")
suites=(${suites[*]})
build=${RSG_FASTDDS3_BUILD:-build-fdds3}
chroot=tools/fastdds3/chroot.sh
targets=(rsg_bench_e2e rsg_bench_relay_cyclone rsg_bench_cyclone_reader rsg_gateway)

$chroot setup
[[ -f $build/CMakeCache.txt ]] ||
  $chroot in cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRSG_FASTDDS=3 \
    -DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache > /dev/null
$chroot in cmake --build "$build" -j "${JOBS:-$(nproc)}" --target "${targets[@]}"
cmake --build "$host_build" -j "${JOBS:-$(nproc)}" --target "${targets[@]}" rsg_sim rsg_bench_reader_host \
  rsg_echo rsg_views_churn

# The host's tools with a 3.x gateway: a script that runs the chroot's build (readers.py counts its
# process tree).
gateway3=$PWD/$build/bench/bin-gateway3
$chroot mixed "$gateway3" "$PWD/$host_build" "$PWD/$build" rsg_gateway
if [[ " ${suites[*]} " == *" readers "* ]]; then
  python3 tests/bench/readers/readers.py --bin "$host_build/bin" --label fastdds2.9 --out "$build/bench/readers"
  python3 tests/bench/readers/readers.py --bin "$host_build/bin" --gateway "$gateway3/rsg_gateway" \
    --label fastdds3 --reader-qos reader_realtime_udp --out "$build/bench/readers"
fi
if [[ " ${suites[*]} " == *" churn "* ]]; then
  # make bench's churn suite with a 3.x gateway (2.9 readers on the host, Jazzy rclpy's Fast DDS 2.14).
  RSG_DEPS_DIR=$(sed -n 's/^RSG_DEPS_DIR:PATH=//p' "$host_build/CMakeCache.txt") \
    python3 tests/bench/readers/churn.py --bin "$gateway3" --label fastdds3 --out "$build/bench/churn" \
    --runs "${RSG_BENCH_CHURN_RUNS:-3}" --gateway-args "${RSG_BENCH_CHURN_GATEWAY_ARGS:---rt-priority 30}"
fi
[[ " ${suites[*]} " == *" e2e "* ]] || exit 0

tests/bench/run_bench.sh "$host_build" e2e > /dev/null
# The chroot starts from an empty environment: the durations and the commit (no git in there) go in.
settings=(RSG_BENCH_COMMIT="$(git describe --always --dirty)")
for name in RSG_BENCH_FULL RSG_BENCH_E2E_SECONDS RSG_BENCH_E2E_STEP_SECONDS RSG_BENCH_E2E_SOAK_SECONDS; do
  [[ -n ${!name:-} ]] && settings+=("$name=${!name}")
done
$chroot in env "${settings[@]}" tests/bench/run_bench.sh "$build" e2e > /dev/null
python3 tests/bench/compare_fastdds.py "$host_build/bench/results.json" "$build/bench/results.json" |
  tee "$build/bench/comparison.md"
