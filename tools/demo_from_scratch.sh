#!/usr/bin/env bash
# What a new user waits for: `git clone` then `make demo` in a fresh Debian 12 container (the
# bookworm-slim base image: no build package, empty apt lists, no compiler cache), each line of the
# output prefixed with the seconds since the clone started. git and make are installed first and not
# timed (cloning needs them). The README's demo figure comes from this script (docs/development.md).
#
#   tools/demo_from_scratch.sh [COMMIT]     default: HEAD of this checkout
#
# Needs a container engine (docker/engine.sh) and host networking; the demo talks to itself only.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
source "$root/docker/engine.sh"
"$root/docker/base-image.sh" "${ENGINE[@]}"
commit=$(git -C "$root" rev-parse "${1:-HEAD}")

"${ENGINE[@]}" run --rm --network host -v "$root:/src:ro" -e RSG_DEMO_SECONDS=15 -e COMMIT="$commit" \
  docker.io/library/debian:bookworm-slim bash -c '
set -eo pipefail
apt-get update -qq > /dev/null
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends git make ca-certificates > /dev/null 2>&1
git config --global --add safe.directory "*"
start=$EPOCHREALTIME
elapsed() { local now=$EPOCHREALTIME; printf "%6d.%d" $(( (${now/./} - ${start/./}) / 1000000 )) $(( (${now/./} - ${start/./}) / 100000 % 10 )); }
git clone -q /src /rsg
git -C /rsg checkout -q "$COMMIT"
cd /rsg
make demo 2>&1 | while IFS= read -r line; do printf "%s %s\n" "$(elapsed)" "$line"; done
echo "$(elapsed) demo_from_scratch: make demo exited ${PIPESTATUS[0]}"
'
