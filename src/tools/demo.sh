#!/usr/bin/env bash
# The built-in demo: simulated robot -> rsg_gateway -> rsg_echo on this machine, for ~10 s, with
# rsg_view serving the live page and Foxglove's WebSocket protocol meanwhile.
#
#   src/tools/demo.sh BIN_DIR [SECONDS]     live table until SECONDS pass or Ctrl-C
#   RSG_DEMO_CHECK=1 src/tools/demo.sh ...  non-interactive: fails unless samples arrive
set -euo pipefail

bin=${1:?usage: demo.sh BIN_DIR [SECONDS]}
seconds=${2:-${RSG_DEMO_SECONDS:-10}}
# A domain and port of its own, so a demo never talks to another demo or a test on this machine
# (the tests' domains are 20-99, their DDS ports below 32768: tests/support/test_domain.py).
domain=${RSG_DEMO_DOMAIN:-$(($$ % 100 + 120))}
port=${RSG_DEMO_PORT:-$((40000 + $$ % 20000))}
# rsg_view's usual port for people; the non-interactive check takes one next to the gateway's.
view_port=${RSG_DEMO_VIEW_PORT:-$([[ -n "${RSG_DEMO_CHECK:-}" ]] && echo $((port + 1)) || echo 8765)}

# rsg_view's messages: shown when the non-interactive check fails, else not at all.
view_log=/dev/null
[[ -n "${RSG_DEMO_CHECK:-}" ]] && view_log=$(mktemp)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  [[ $view_log == /dev/null ]] || rm -f "$view_log"
}
trap cleanup EXIT
trap 'exit 0' INT TERM

echo "rsg demo: rsg_sim -> udp://127.0.0.1:$port -> rsg_gateway -> DDS domain $domain -> rsg_echo, ${seconds} s"
"$bin/rsg_gateway" --listen "127.0.0.1:$port" --domain "$domain" --log-level warn &
pids+=($!)
"$bin/rsg_view" --domain "$domain" --listen "127.0.0.1:$view_port" 2>"$view_log" &
pids+=($!)

# The page's HTML from rsg_view, fetched with bash alone (no curl on a minimal Debian).
page_served() {
  local reply
  exec 3<>"/dev/tcp/127.0.0.1/$view_port" || return 1
  printf 'GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n' >&3
  reply=$(timeout 5 cat <&3)
  exec 3<&-
  [[ $reply == "HTTP/1.1 200"*"<title>rsg_view</title>"* ]]
}

if [[ -n "${RSG_DEMO_CHECK:-}" ]]; then
  "$bin/rsg_sim" --to "127.0.0.1:$port" --rate 1000 --duration "$seconds" 2>/dev/null &
  pids+=($!)
  # The pipeline end to end: 100 samples of the kinematics view as canonical JSON.
  "$bin/rsg_echo" --domain "$domain" --view view_kinematics --json --count 100 --timeout "$seconds" > /dev/null
  echo "rsg demo: OK, 100 samples received"
  for _ in $(seq 50); do page_served 2>/dev/null && { echo "rsg demo: OK, rsg_view serves the page"; exit 0; }; sleep 0.2; done
  echo "rsg demo: rsg_view did not serve its page on 127.0.0.1:$view_port; it said:" >&2
  cat "$view_log" >&2
  exit 1
fi

echo "rsg demo: watch it at http://127.0.0.1:$view_port/ or in Foxglove / PlotJuggler at ws://127.0.0.1:$view_port" \
  "(RSG_DEMO_SECONDS=600 make demo for a longer look)"
# Kinematics (groups 0, 2) and status (5) in every frame, inertias (1) in every 100th: the
# kinematics view then gets every frame, so the table's packet-number gaps mean real loss.
"$bin/rsg_echo" --domain "$domain" --view view_kinematics --qos reader_logger &
pids+=($!)
"$bin/rsg_sim" --to "127.0.0.1:$port" --rate 1000 --duration "$seconds" \
  --every 1:g0,g2,g5 --every 100:g1 2>/dev/null
