#!/bin/sh
# Prints the Debian packages that own the shared libraries the given programs load (ldd), one a
# line, and fails when a library is not found or no package owns it: a missing runtime package must
# fail the image build, not a container at start. ldd prints the loader's path (/lib/x86_64-linux-gnu
# on a merged-/usr system) while dpkg may know the file under /usr/lib, or the other way round: each
# library is looked up as printed, as resolved (realpath), and under the other prefix.
#
#   runtime-packages.sh PROGRAM...
set -eu
[ $# -gt 0 ] || { echo "usage: $0 PROGRAM..." >&2; exit 2; }
libraries=$(mktemp)
packages=$(mktemp)
trap 'rm -f "$libraries" "$packages"' EXIT
status=0
for program in "$@"; do
  out=$(ldd "$program") || { echo "runtime-packages: ldd failed on $program" >&2; exit 1; }
  if echo "$out" | grep -q 'not found'; then
    echo "runtime-packages: $program: $(echo "$out" | grep 'not found' | tr -s ' \t' ' ')" >&2
    status=1
  fi
  echo "$out" | awk '$2 == "=>" && $3 ~ /^\// { print $3 } $1 ~ /^\// { print $1 }' >> "$libraries"
done

# The package that owns PATH, or nothing.
owner() {
  dpkg-query -S "$1" 2>/dev/null | awk -F': ' -v path="$1" '$2 == path { print $1 }' | tr ',' '\n' |
    sed 's/^ *//; s/:.*//' | head -n 1
}
for library in $(sort -u "$libraries"); do
  resolved=$(realpath "$library")
  package=""
  for candidate in "$library" "$resolved" "/usr$library" "${library#/usr}" "/usr$resolved" "${resolved#/usr}"; do
    package=$(owner "$candidate")
    [ -z "$package" ] || break
  done
  if [ -z "$package" ]; then
    echo "runtime-packages: no Debian package owns $library ($resolved)" >&2
    status=1
  else
    echo "$package" >> "$packages"
  fi
done
sort -u "$packages"
exit $status
