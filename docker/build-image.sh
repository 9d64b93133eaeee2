#!/usr/bin/env bash
# make image: builds docker/Dockerfile as IMAGE (default rsg) with the engine that works here
# (docker/engine.sh); with podman and no debian:bookworm-slim yet, first makes that base image from
# Debian's mirror (docker/base-image.sh), since no image registry may be reachable. Prints the
# build time and what the runtime stage adds on top of its base.
set -euo pipefail
cd "$(dirname "$0")/.."
image=${1:-rsg}
source docker/engine.sh
echo "image: building $image with ${ENGINE[*]}"
build=(build -f docker/Dockerfile -t "$image" .)
if [[ $ENGINE_NAME == podman ]]; then
  docker/base-image.sh "${ENGINE[@]}"
  # The docker format keeps HEALTHCHECK (OCI has none); the host network, as RUN steps reach the
  # mirror here only through it; the ignore file docker reads next to the Dockerfile.
  build=(build --format docker --network host --ignorefile docker/Dockerfile.dockerignore "${build[@]:1}")
fi
start=$(date +%s)
"${ENGINE[@]}" "${build[@]}"
# The CPU of this script's children: the base image (if made) and the build (with podman its RUN steps too).
cpu_file=$(mktemp)
times > "$cpu_file"  # not in $(...): a subshell has no children
cpu=$(tail -n 1 "$cpu_file")
rm -f "$cpu_file"
echo "image: built $image in $(( $(date +%s) - start )) s, CPU (base image and build): ${cpu% *} user, ${cpu#* } system"
# What the runtime stage adds to its base: the image's size less debian:bookworm-slim's.
size() { "${ENGINE[@]}" image inspect --format '{{.Size}}' "$1"; }
total=$(size "$image")
base=$(size docker.io/library/debian:bookworm-slim 2>/dev/null || size debian:bookworm-slim)
echo "image: $image is $(( total / 1000000 )) MB, $(( (total - base) / 1000000 )) MB over debian:bookworm-slim ($(( base / 1000000 )) MB)"
