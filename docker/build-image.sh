#!/usr/bin/env bash
# make image: builds docker/Dockerfile as IMAGE (default rsg) with the engine that works here
# (docker/engine.sh); with podman and no debian:bookworm-slim yet, first makes that base image from
# Debian's mirror (docker/base-image.sh), since no image registry may be reachable. Prints the
# build time and what the runtime stage adds on top of its base.
#
#   docker/build-image.sh [IMAGE]                          # compiles the tools in the build stage
#   docker/build-image.sh --tools-from BUILD_TREE [IMAGE]  # installs a Release tree already built
#
# --tools-from takes a CMake tree configured as the build stage is (Release, RSG_BUILD_TESTS=OFF, on
# Debian 12 with docker/packages/build.txt: make package's tree is one) and installs it, stripped,
# into build-image/opt/rsg, which the Dockerfile's `prebuilt` stage copies: make test-image builds
# the image from the binaries make package compiled, not from a second compile of the same sources.
set -euo pipefail
cd "$(dirname "$0")/.."
tools_from=
if [[ ${1:-} == --tools-from ]]; then
  tools_from=${2:?--tools-from needs a build tree}
  shift 2
fi
image=${1:-rsg}
source docker/engine.sh
build=(build -f docker/Dockerfile -t "$image")
if [[ -n $tools_from ]]; then
  [[ -f $tools_from/CMakeCache.txt ]] || { echo "image: $tools_from is not a CMake build tree" >&2; exit 1; }
  grep -q '^RSG_BUILD_TESTS:BOOL=OFF$' "$tools_from/CMakeCache.txt" ||
    { echo "image: $tools_from was configured with the tests; the image takes a tree without (make package's)" >&2; exit 1; }
  cmake --build "$tools_from" -j "$(nproc)"
  rm -rf build-image
  cmake --install "$tools_from" --prefix "$PWD/build-image/opt/rsg" --strip > /dev/null
  cp -r ros2/rsg_msgs build-image/opt/rsg/share/rsg/
  docker/runtime-packages.sh build-image/opt/rsg/bin/* > build-image/opt/rsg/share/rsg/runtime-packages.txt
  echo "image: the tools of $tools_from, needing: $(tr '\n' ' ' < build-image/opt/rsg/share/rsg/runtime-packages.txt)"
  build+=(--build-arg RSG_TOOLS=prebuilt)
fi
build+=(.)
echo "image: building $image with ${ENGINE[*]}"
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
