#!/usr/bin/env bash
# make test-image: builds the image (docker/build-image.sh) and runs tests/image/test_image.py with
# the same engine. Extra arguments go to the test, e.g. --case pipeline.
set -euo pipefail
cd "$(dirname "$0")/../.."
image=${RSG_IMAGE:-rsg}
# RSG_IMAGE_TOOLS_FROM: a Release tree without tests to install instead of compiling in the image.
docker/build-image.sh ${RSG_IMAGE_TOOLS_FROM:+--tools-from "$RSG_IMAGE_TOOLS_FROM"} "$image"
source docker/engine.sh
# Debian's Python: its python3-yaml reads compose.yaml (make deps installs it).
exec /usr/bin/python3 tests/image/test_image.py --engine "${ENGINE[*]}" --image "$image" "$@"
