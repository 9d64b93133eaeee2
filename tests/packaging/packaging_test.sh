#!/usr/bin/env bash
# The image and a developer machine install the same packages: docker/packages/{build,run,test}.txt
# are the only lists, the image installs build.txt to build and run.txt to run, never test.txt.
# (make test-image is the real proof: tests/image builds the image and runs it.)
set -euo pipefail
root=${1:?usage: packaging_test.sh SOURCE_DIR}
cd "$root"
fail() { echo "FAIL: $*"; exit 1; }

grep -q '^COPY docker/packages/build.txt ' docker/Dockerfile || fail "Dockerfile's build stage does not copy build.txt"
grep -q '^COPY docker/packages/run.txt ' docker/Dockerfile || fail "Dockerfile's runtime stage does not copy run.txt"
grep -q 'test.txt' docker/Dockerfile && fail "the image installs the test packages"
# No second, hand-kept package list inside the Dockerfile.
if grep -E 'apt-get install[^<|]*\b(lib[a-z0-9-]+-dev|cmake|fastddsgen)\b' docker/Dockerfile; then
  fail "Dockerfile names build packages itself"
fi
grep -q 'docker/packages/' Makefile || fail "make deps does not read docker/packages/"

# Every listed package is a real, installed Debian package (make deps ran before the tests).
missing=()
for list in docker/packages/{build,run,test,package}.txt; do
  while read -r package; do
    [[ -z "$package" || "$package" == \#* ]] && continue
    dpkg-query -W -f='${Status}\n' "$package" 2>/dev/null | grep -q 'install ok installed' || missing+=("$package")
  done < "$list"
done
[[ ${#missing[@]} -eq 0 ]] || fail "listed but not installed: ${missing[*]}"

# docker/runtime-packages.sh, which the image build runs on every tool: the packages of the libraries
# a program loads (ldd prints /lib/..., dpkg may know /usr/lib/...), and a failure that names a
# library no package owns.
packages=$(docker/runtime-packages.sh /bin/ls) || fail "runtime-packages.sh /bin/ls failed"
grep -qx libc6 <<< "$packages" || fail "runtime-packages.sh /bin/ls does not name libc6: $packages"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
library=$(ldd /bin/ls | awk '$1 !~ /^(libc|linux-vdso)/ && $3 ~ /^\// { print $3; exit }')
cp "$library" "$scratch/"
if LD_LIBRARY_PATH=$scratch docker/runtime-packages.sh /bin/ls > /dev/null 2> "$scratch/err"; then
  fail "runtime-packages.sh passed with $scratch/$(basename "$library"), which no package owns"
fi
grep -q "no Debian package owns $scratch/$(basename "$library")" "$scratch/err" ||
  fail "runtime-packages.sh did not name the unowned library: $(cat "$scratch/err")"

# The compose file runs binaries the image installs.
for tool in $(grep -oE 'rsg_[a-z_]+' docker/compose.yaml | sort -u); do
  grep -q "$tool" CMakeLists.txt || fail "compose.yaml runs $tool, which is not installed"
done
echo "packaging: OK"
