#!/usr/bin/env bash
# make test-image: builds the image (docker/build-image.sh) and runs tests/image/test_image.py with
# the same engine. Extra arguments go to the test, e.g. --case pipeline.
set -euo pipefail
cd "$(dirname "$0")/../.."
image=${RSG_IMAGE:-rsg}
docker/build-image.sh "$image"
source docker/engine.sh
# Debian's Python: its python3-yaml reads compose.yaml (make deps installs it).
exec /usr/bin/python3 tests/image/test_image.py --engine "${ENGINE[*]}" --image "$image" "$@"
