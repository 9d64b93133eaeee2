#!/usr/bin/env bash
# One virtual environment per requirements file: tools/deps/python/NAME.txt -> $DEPS_DIR/NAME.
# Every file pins its packages with hashes (pip --require-hashes); an environment is made again
# only when its file changed. Debian's /usr/bin/python3 (3.11 on Debian 12) is the interpreter, so
# the environments do not depend on whichever python3 comes first on PATH.
set -euo pipefail
cd "$(dirname "$0")/../.."
deps_dir=${DEPS_DIR:-$PWD/.deps}
python=${RSG_DEPS_PYTHON:-/usr/bin/python3}
shopt -s nullglob
for requirements in tools/deps/python/*.txt; do
  name=$(basename "$requirements" .txt)
  env_dir=$deps_dir/$name
  stamp=$(sha256sum "$requirements" | cut -d' ' -f1)
  [[ -f $env_dir/.rsg-stamp && $(<"$env_dir/.rsg-stamp") == "$stamp" ]] && continue
  echo "make deps: Python environment $env_dir from $requirements"
  rm -rf "$env_dir"
  "$python" -m venv "$env_dir"
  "$env_dir/bin/pip" install --quiet --disable-pip-version-check --no-input \
    --require-hashes --only-binary=:all: -r "$requirements"
  echo "$stamp" > "$env_dir/.rsg-stamp"
done
