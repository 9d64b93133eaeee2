#!/usr/bin/env bash
# Go tools of the tests, from the Go module proxy, pinned by tools/deps/go/go.mod and go.sum:
# $DEPS_DIR/bin/rsg-mcap-check, tools/deps/go/mcapcheck built on MCAP's own Go library
# (github.com/foxglove/mcap/go/mcap). GOPATH lives under $DEPS_DIR; the module and build caches
# too, unless RSG_CACHE_DIR names a cache the checkouts of this machine share (make sets it to
# ~/.cache/rsg, as ccache's is ~/.cache/ccache: a fresh clone then builds the tool from the cache).
# The tool is built again only when tools/deps/go/ changed. (The official `mcap` CLI module,
# github.com/foxglove/mcap/go/cli/mcap, is not served by the proxy: docs/mcap-tested.md.)
set -euo pipefail
cd "$(dirname "$0")/../.."
deps_dir=${DEPS_DIR:-$PWD/.deps}
go=${RSG_DEPS_GO:-$(command -v go || echo /usr/local/go/bin/go)}
if [[ ! -x $go ]]; then
  echo "make deps: no Go toolchain (go on PATH or /usr/local/go/bin/go) to build rsg-mcap-check" >&2
  exit 1
fi
stamp=$(cat tools/deps/go/go.mod tools/deps/go/go.sum tools/deps/go/*/*.go | sha256sum | cut -d' ' -f1)
bin=$deps_dir/bin/rsg-mcap-check
[[ -x $bin && -f $bin.rsg-stamp && $(<"$bin.rsg-stamp") == "$stamp" ]] && exit 0
echo "make deps: building $bin from tools/deps/go"
mkdir -p "$deps_dir/bin"
go_cache=${RSG_CACHE_DIR:+$RSG_CACHE_DIR/go}
go_cache=${go_cache:-$deps_dir/go}
export GOPATH=$deps_dir/go GOMODCACHE=$go_cache/pkg/mod GOCACHE=$go_cache/cache
export GOFLAGS="-mod=readonly -buildvcs=false" GOTOOLCHAIN=local GOWORK=off CGO_ENABLED=0
(cd tools/deps/go && "$go" build -trimpath -o "$bin" ./mcapcheck)
echo "$stamp" > "$bin.rsg-stamp"
