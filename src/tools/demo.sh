#!/usr/bin/env bash
# The built-in demo: simulated robot -> rsg_gateway -> rsg_echo, on this machine, for ~10 s.
#
#   src/tools/demo.sh BIN_DIR [SECONDS]     live table until SECONDS pass or Ctrl-C
#   RSG_DEMO_CHECK=1 src/tools/demo.sh ...  non-interactive: fails unless samples arrived
set -euo pipefail

bin=${1:?usage: demo.sh BIN_DIR [SECONDS]}
seconds=${2:-${RSG_DEMO_SECONDS:-10}}
# A domain and port of its own, so a demo never talks to another demo or a test on this machine.
domain=${RSG_DEMO_DOMAIN:-$(($$ % 100 + 120))}
port=${RSG_DEMO_PORT:-$((20000 + $$ % 20000))}

pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
}
trap cleanup EXIT INT TERM

echo "rsg demo: sim -> udp://127.0.0.1:$port -> rsg_gateway -> DDS domain $domain -> rsg_echo ($seconds s)"
"$bin/rsg_gateway" --listen "127.0.0.1:$port" --domain "$domain" &
pids+=($!)
"$bin/rsg_sim" --to "127.0.0.1:$port" --rate 1000 --duration "$((seconds + 2))" \
  --every 1:g2,g5 --every 10:g0 --every 100:g1 2>/dev/null &
pids+=($!)

if [[ -n "${RSG_DEMO_CHECK:-}" ]]; then
  # Prove the pipeline end to end: 100 samples as canonical JSON within the time box.
  "$bin/rsg_echo" --domain "$domain" --json --count 100 --timeout "$seconds" > /dev/null
  echo "rsg demo: OK, 100 samples received"
else
  "$bin/rsg_echo" --domain "$domain" --view view_kinematics --timeout "$seconds" || true
fi
