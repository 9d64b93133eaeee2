#!/usr/bin/env bash
# Makes docker.io/library/debian:bookworm-slim locally, for an engine that reaches no image
# registry: `debootstrap --variant=minbase` from the Debian mirror the host's apt already uses,
# slimmed the way Debian's official slim image is (no docs but copyrights, no man/info pages, no
# translations, no apt lists or downloaded .debs, and a dpkg configuration that keeps later
# installs slim too), then imported. Does nothing when the image exists.
#
#   docker/base-image.sh podman [ENGINE FLAGS...]
set -euo pipefail
engine=("$@")
[[ ${#engine[@]} -gt 0 ]] || { echo "usage: $0 ENGINE [FLAGS...]" >&2; exit 2; }
image=docker.io/library/debian:bookworm-slim
if "${engine[@]}" image inspect "$image" >/dev/null 2>&1; then
  echo "base image: $image exists"
  exit 0
fi

source "$(dirname "$0")/../tools/apt_sources.sh"  # apt_uri
mirror=$(apt_uri bookworm)
[[ -n "$mirror" ]] || { echo "base image: no Debian bookworm source in /etc/apt: which mirror?" >&2; exit 1; }
security=$(apt_uri bookworm-security)
command -v debootstrap >/dev/null || { echo "base image: debootstrap is missing (make deps installs it)" >&2; exit 1; }

root=$(mktemp -d "${TMPDIR:-/var/tmp}/rsg-bookworm.XXXXXX")
trap 'rm -rf "$root"' EXIT
echo "base image: debootstrap --variant=minbase bookworm from $mirror"
debootstrap --variant=minbase bookworm "$root" "$mirror" > "$root.log" 2>&1 ||
  { tail -n 20 "$root.log" >&2; rm -f "$root.log"; exit 1; }
rm -f "$root.log"

# The image's apt reads the same mirror, with updates and (if the host has it) security.
{
  echo "deb $mirror bookworm main"
  echo "deb $mirror bookworm-updates main"
  [[ -z "$security" ]] || echo "deb $security bookworm-security main"
} > "$root/etc/apt/sources.list"

# What Debian's slim image leaves out, now and for every later dpkg install in the image.
cat > "$root/etc/dpkg/dpkg.cfg.d/slim" <<'CFG'
path-exclude /usr/share/doc/*
path-include /usr/share/doc/*/copyright
path-exclude /usr/share/man/*
path-exclude /usr/share/info/*
path-exclude /usr/share/groff/*
path-exclude /usr/share/lintian/*
path-exclude /usr/share/linda/*
path-exclude /usr/share/locale/*
CFG
# Files only: maintainer scripts expect the folders (openjdk's postinst links into man/man1).
for dir in "$root"/usr/share/{doc,man,info,groff,lintian,linda,locale}; do
  [[ ! -d "$dir" ]] || find "$dir" -not -type d -not -path "$root/usr/share/doc/*/copyright" -delete
done
rm -rf "$root"/var/cache/apt/*.bin "$root"/var/cache/apt/archives/*.deb \
       "$root"/var/lib/apt/lists/* "$root"/var/log/* "$root"/tmp/* "$root"/var/tmp/*
# apt keeps no downloaded .debs and no binary caches after an install.
cat > "$root/etc/apt/apt.conf.d/slim" <<'CFG'
APT::Keep-Downloaded-Packages "false";
Dir::Cache::pkgcache "";
Dir::Cache::srcpkgcache "";
CFG

echo "base image: $(du -sm "$root" | cut -f1) MB tree, importing as $image"
tar --numeric-owner -C "$root" -c . | "${engine[@]}" import --change 'CMD ["bash"]' - "$image"
