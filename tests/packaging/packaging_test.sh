#!/usr/bin/env bash
# The image and a developer machine install the same packages: docker/packages.txt is the only list.
set -euo pipefail
root=${1:?usage: packaging_test.sh SOURCE_DIR}
cd "$root"
fail() { echo "FAIL: $*"; exit 1; }

grep -q '^COPY docker/packages.txt ' docker/Dockerfile || fail "Dockerfile does not copy docker/packages.txt"
grep -q 'grep -v .*/tmp/packages.txt | xargs apt-get install' docker/Dockerfile ||
  fail "Dockerfile's build stage does not install from docker/packages.txt"
# No second, hand-kept package list inside the Dockerfile.
if grep -E 'apt-get install[^<|]*\b(lib[a-z0-9-]+-dev|cmake|fastddsgen)\b' docker/Dockerfile; then
  fail "Dockerfile names build packages itself"
fi
grep -q 'docker/packages.txt' Makefile || fail "make deps does not read docker/packages.txt"

# Every listed package is a real, installed Debian package (make deps ran before the tests).
missing=()
while read -r package; do
  [[ -z "$package" || "$package" == \#* ]] && continue
  dpkg-query -W -f='${Status}\n' "$package" 2>/dev/null | grep -q 'install ok installed' || missing+=("$package")
done < docker/packages.txt
[[ ${#missing[@]} -eq 0 ]] || fail "listed but not installed: ${missing[*]}"

# The compose file runs binaries the image installs.
for tool in $(grep -oE 'rsg_[a-z_]+' docker/compose.yaml | sort -u); do
  grep -q "$tool" CMakeLists.txt || fail "compose.yaml runs $tool, which is not installed"
done
echo "packaging: OK"
