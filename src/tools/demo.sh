#!/usr/bin/env bash
# The built-in demo: simulated robot -> rsg_gateway -> rsg_echo on this machine, for ~10 s.
#
#   src/tools/demo.sh BIN_DIR [SECONDS]     live table until SECONDS pass or Ctrl-C
#   RSG_DEMO_CHECK=1 src/tools/demo.sh ...  non-interactive: fails unless samples arrive
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
trap cleanup EXIT
trap 'exit 0' INT TERM

echo "rsg demo: rsg_sim -> udp://127.0.0.1:$port -> rsg_gateway -> DDS domain $domain -> rsg_echo, ${seconds} s"
"$bin/rsg_gateway" --listen "127.0.0.1:$port" --domain "$domain" --log-level warn &
pids+=($!)

if [[ -n "${RSG_DEMO_CHECK:-}" ]]; then
  "$bin/rsg_sim" --to "127.0.0.1:$port" --rate 1000 --duration "$seconds" 2>/dev/null &
  pids+=($!)
  # The pipeline end to end: 100 samples of the kinematics view as canonical JSON.
  "$bin/rsg_echo" --domain "$domain" --view view_kinematics --json --count 100 --timeout "$seconds" > /dev/null
  echo "rsg demo: OK, 100 samples received"
  exit 0
fi

# Kinematics (groups 0, 2) and status (5) in every frame, inertias (1) in every 100th: the
# kinematics view then gets every frame, so the table's packet-number gaps mean real loss.
"$bin/rsg_echo" --domain "$domain" --view view_kinematics --qos reader_logger &
pids+=($!)
"$bin/rsg_sim" --to "127.0.0.1:$port" --rate 1000 --duration "$seconds" \
  --every 1:g0,g2,g5 --every 100:g1 2>/dev/null
