#!/usr/bin/env bash
# make test-service: the .deb of `make package` ($PKG_BUILD/packages), the same package again with a
# lower version (the upgrade's starting point: `cpack -D CPACK_PACKAGE_VERSION=<version>~older`, same
# binaries), the image of tests/service/Containerfile (podman only: --systemd=always), then
# tests/service/test_service.py. Fails, never skips, when something it needs is missing.
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${PKG_BUILD:-build-pkg}
image=${RSG_SERVICE_IMAGE:-rsg-service-test}
start=$SECONDS
RSG_ENGINE=podman source docker/engine.sh
[[ $ENGINE_NAME == podman ]] || { echo "test-service: needs podman (--systemd=always)" >&2; exit 1; }

shopt -s nullglob
debs=("$build"/packages/rsg_*.deb)
[[ ${#debs[@]} -eq 1 ]] || { echo "test-service: expected one $build/packages/rsg_*.deb (make package), found ${#debs[@]}" >&2; exit 1; }
deb=${debs[0]}
version=$(dpkg-deb -f "$deb" Version)

# The package itself: a man page for every tool in /usr/bin, and lintian's warnings exactly the
# ones docs/service.md lists and justifies (make package already failed on any error).
contents=$(dpkg-deb -c "$deb" | awk '{ print $6 }')
for tool in $(grep -oE '^\./usr/bin/[^/]+$' <<< "$contents" | xargs -n1 basename); do
  grep -qx "./usr/share/man/man1/$tool.1.gz" <<< "$contents" || { echo "test-service: no man page for $tool in $deb" >&2; exit 1; }
done
allowed='maintainer-script-calls-systemctl'
tags=$(lintian "$deb" 2> /dev/null | awk '$1 ~ /^[EW]:$/ { print $3 }' | sort -u)
unlisted=$(grep -vxE "$allowed" <<< "$tags" || true)
[[ -z "$unlisted" ]] || { echo "test-service: lintian tags not listed in docs/service.md: $unlisted" >&2; exit 1; }
echo "test-service: $(basename "$deb"): a man page per tool; lintian: ${tags:-nothing} (listed in docs/service.md)"
work=$(mktemp -d "${TMPDIR:-/tmp}/rsg-service.XXXXXX")
trap 'rm -rf "$work"' EXIT
cp "$deb" "$work/"
(cd "$build" && cpack -G DEB -D CPACK_PACKAGE_VERSION="$version~older" -B "$work/older" > "$work/cpack.log") ||
  { cat "$work/cpack.log" >&2; exit 1; }
old=("$work"/older/rsg_*.deb)
[[ ${#old[@]} -eq 1 ]] || { echo "test-service: cpack made no older package" >&2; exit 1; }
cp "${old[0]}" "$work/"
chmod -R a+rX "$work"

docker/base-image.sh "${ENGINE[@]}"
"${ENGINE[@]}" build --format docker --network host -t "$image" -f tests/service/Containerfile tests/service > "$work/image.log" 2>&1 ||
  { tail -n 30 "$work/image.log" >&2; exit 1; }
echo "test-service: $(basename "$deb") and $(basename "${old[0]}"), image $image ready after $((SECONDS - start)) s"
status=0
/usr/bin/python3 tests/service/test_service.py --engine "${ENGINE[*]}" --image "$image" --deb "$work/$(basename "$deb")" \
  --old-deb "$work/$(basename "${old[0]}")" --bin "$build/bin" "$@" || status=$?
echo "test-service: took $((SECONDS - start)) s"
exit $status
