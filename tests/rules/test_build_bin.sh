#!/usr/bin/env bash
# build/bin holds exactly the executables `make install` installs (CONTRIBUTING.md, "Build tree"):
# the README puts it on PATH, so a test, a test helper or a benchmark built there would reach the
# user's shell. The installed list is the install rules' own (the runtime component into a scratch
# prefix), not a copy of it.
set -euo pipefail
build_dir=${1:?usage: test_build_bin.sh BUILD_DIR}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cmake --install "$build_dir" --prefix "$work/prefix" --component runtime > "$work/install.log"
installed=$(cd "$work/prefix/bin" && ls)
built=$(cd "$build_dir/bin" && ls)
if [[ $installed != "$built" ]]; then
  echo "FAIL: $build_dir/bin is not what make install installs"
  echo "in $build_dir/bin, not installed:" $(comm -13 <(echo "$installed") <(echo "$built"))
  echo "installed, not in $build_dir/bin:" $(comm -23 <(echo "$installed") <(echo "$built"))
  echo "(everything but the installed tools goes to $build_dir/tests/bin: RSG_TOOLS in CMakeLists.txt)"
  exit 1
fi
echo "build_bin: OK ($(echo "$installed" | wc -w) tools:" $installed")"
