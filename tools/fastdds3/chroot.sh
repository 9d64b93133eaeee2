#!/usr/bin/env bash
# The Debian 13 (trixie) test bed of the Fast DDS 3 build (docs/fastdds-versions.md): Fast DDS 3.6.1
# from Debian experimental, with Fast CDR 2.3 and fastddsgen 4.3 from unstable, on trixie
# (tools/fastdds3/apt-preferences says which package comes from which suite).
#
#   tools/fastdds3/chroot.sh setup         make the chroot once (cached), install docker/packages/trixie.txt
#   tools/fastdds3/chroot.sh run CMD...    run CMD on the host with the chroot's file systems mounted
#   tools/fastdds3/chroot.sh in CMD...     run CMD inside the chroot, in the same directory (the checkout
#                                          is mounted at its own path; RSG_CHROOT_ENV="A=1 B=2" passes
#                                          variables in)
#   tools/fastdds3/chroot.sh mixed DIR HOST_BUILD CHROOT_BUILD TOOL...
#                                          make DIR a bin directory of HOST_BUILD's executables (2.9:
#                                          bin/ and tests/bin/) in which each TOOL is a script running
#                                          CHROOT_BUILD's (3.x) in the chroot: the cross-version tests
#                                          and benchmarks take it as --bin
#
# The chroot lives in the git-ignored $RSG_TRIXIE_DIR (default .deps/trixie). `run` and `in` work in
# a private mount namespace (unshare -m): /proc, /sys, /dev, /dev/shm, /tmp (files the tests hand
# over) and the checkout are mounted
# into the chroot there only, are never seen by the host's other processes, unmounted by the trap
# below and in any case by the kernel when the namespace's last process ends. So an `rm -rf` of the
# chroot from outside never walks into a bind mount. The chroot shares the host's network (the
# cross-version tests put a 2.9 process on the host and a 3.x process in the chroot on one domain).
#
# The chroot's compiler cache lives beside the host's ($CCACHE_DIR, else ccache's own directory,
# with "-trixie" added; RSG_TRIXIE_CCACHE_DIR to choose), outside the checkout, mounted at its own
# path: a fresh clone (CI's) then builds its Fast DDS 3 tree from the objects of the last build on
# this machine, as the host's trees do, instead of compiling it whole (about 10 minutes). A
# directory of its own, since Debian 13's ccache is newer than the host's.
set -euo pipefail
checkout=$(cd "$(dirname "$0")/../.." && pwd)
root=${RSG_TRIXIE_DIR:-$checkout/.deps/trixie}
ccache_dir=${RSG_TRIXIE_CCACHE_DIR:-${CCACHE_DIR:-$(ccache -k cache_dir 2>/dev/null || echo "$checkout/.cache/ccache")}-trixie}
source "$checkout/tools/apt_sources.sh"  # debian_mirror
# The Debian mirror the host's apt uses (a Debian 12 host lists bookworm, a 13 host trixie), or
# RSG_TRIXIE_MIRROR; looked up where it is needed (setup), since `run` and `in` need none.
mirror=${RSG_TRIXIE_MIRROR:-}
packages_file=$checkout/docker/packages/trixie.txt
preferences_file=$checkout/tools/fastdds3/apt-preferences

die() { echo "chroot.sh: $*" >&2; exit 1; }
[[ $(id -u) == 0 ]] || die "needs root (debootstrap, chroot, mount)"

# Fails when anything is still mounted below $1 in this mount namespace.
assert_unmounted() {
  if findmnt -rn -o TARGET | grep -q "^$1/"; then die "$1 still has mounts: not touching it"; fi
}

setup() {
  if [[ ! -f $root/.rsg-debootstrap ]]; then
    assert_unmounted "$root.tmp"
    rm -rf "$root.tmp"
    command -v debootstrap >/dev/null || die "debootstrap missing: apt-get install debootstrap"
    [[ -n $mirror ]] || mirror=$(debian_mirror trixie bookworm) ||
      die "no Debian trixie or bookworm source in /etc/apt: which mirror? (RSG_TRIXIE_MIRROR=URI)"
    echo "chroot.sh: debootstrap trixie into $root from $mirror (once)"
    debootstrap --variant=minbase trixie "$root.tmp" "$mirror" > "$checkout/.deps/trixie-debootstrap.log" 2>&1 ||
      die "debootstrap failed: $checkout/.deps/trixie-debootstrap.log"
    touch "$root.tmp/.rsg-debootstrap"
    assert_unmounted "$root"
    rm -rf "$root"
    mv "$root.tmp" "$root"
  fi
  local stamp
  stamp=$(cat "$packages_file" "$preferences_file" | sha256sum | cut -d' ' -f1)
  if [[ ! -f $root/.rsg-packages || $(<"$root/.rsg-packages") != "$stamp" ]]; then
    local packages
    packages=$(grep -v '^\s*#' "$packages_file" | xargs)
    # unstable and experimental beside trixie, from the same mirror, pinned by the preferences file.
    # Their Release files carry a Valid-Until a week ahead (trixie's, a stable release's, none), which
    # a mirror or proxy that serves a snapshot is past: that check is off for these two suites only;
    # the signatures are still checked.
    [[ -n $mirror ]] || mirror=$(debian_mirror trixie bookworm) ||
      die "no Debian trixie or bookworm source in /etc/apt: which mirror? (RSG_TRIXIE_MIRROR=URI)"
    printf 'Types: deb\nURIs: %s\nSuites: unstable experimental\nComponents: main\nCheck-Valid-Until: no\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
      "$mirror" > "$root/etc/apt/sources.list.d/rsg-fastdds.sources"
    mkdir -p "$root/etc/apt/preferences.d"
    grep -v '^#' "$preferences_file" > "$root/etc/apt/preferences.d/rsg-fastdds"
    echo "chroot.sh: installing into the chroot: $packages"
    in_chroot sh -c "apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq \
      --no-install-recommends $packages > /tmp/rsg-apt.log 2>&1 || { tail -30 /tmp/rsg-apt.log; exit 1; }"
    echo "$stamp" > "$root/.rsg-packages"
  fi
}

# Mounts (in the current, private, mount namespace) and unmounts on exit, in reverse order.
mounted=()
unmount_all() {
  local i
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do umount "${mounted[i]}" 2>/dev/null || umount -l "${mounted[i]}" || true; done
}
mount_all() {
  trap unmount_all EXIT
  local target
  mount --make-rprivate /
  mkdir -p "$ccache_dir"
  for spec in "proc proc" "sysfs sys" "bind dev" "bind dev/shm" "bind dev/pts" "bind tmp" "bind $checkout" \
              "bind $ccache_dir"; do
    set -- $spec
    case $1 in
      proc) target=$root/proc; mount -t proc proc "$target" ;;
      sysfs) target=$root/sys; mount -t sysfs sysfs "$target" ;;
      bind)
        local source=/${2#/}
        target=$root$source
        mkdir -p "$target"
        mount --bind "$source" "$target"
        ;;
    esac
    mounted+=("$target")
  done
  cp /etc/resolv.conf "$root/etc/resolv.conf" 2>/dev/null || true
}

# CMD inside the chroot, in a mount namespace of its own.
in_chroot() {
  if [[ ${RSG_TRIXIE_MOUNTED:-} != "$root" ]]; then
    (exec_in_namespace in "$@")
    return
  fi
  # In the background so that the trap can pass SIGTERM and SIGINT on (a test stopping its child)
  # and still unmount after; stdin stays the caller's. A SIGKILL cannot be passed on (a test harness
  # killing its children on failure): the kernel sends CMD SIGTERM when this shell dies (setpriv's
  # parent-death signal, kept across chroot's, env's and sh's exec; the subshell execs, so that the
  # parent is this shell, not a copy of it).
  (exec setpriv --pdeathsig TERM chroot "$root" /usr/bin/env -i HOME=/root \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    LANG=C.UTF-8 CCACHE_DIR="$ccache_dir" CCACHE_BASEDIR="$checkout" \
    CCACHE_NOHASHDIR=true ${CI:+CI=$CI} ${RSG_CHROOT_ENV:-} \
    sh -c 'cd "$0" 2>/dev/null || cd /; exec "$@"' "$PWD" "$@") <&0 &
  child=$!
  trap 'kill -TERM $child 2>/dev/null' TERM
  trap 'kill -INT $child 2>/dev/null' INT
  local status=0
  while :; do
    wait $child && status=0 || status=$?
    kill -0 $child 2>/dev/null || break  # wait was interrupted by a trapped signal: wait again
  done
  return $status
}

# SIGINT back to its default on the way: started from a background job this script gets it
# ignored, and bash can neither trap nor reset a signal it inherits ignored, so in_chroot could not
# pass it on.
exec_in_namespace() {
  exec unshare --mount --propagation private -- env --default-signal=INT RSG_TRIXIE_MOUNTED="$root" "$0" \
    __mounted "$@"
}

# A build tree keeps the installed tools in bin/ and every other executable in tests/bin/
# (CONTRIBUTING.md, "Build tree"); DIR has both kinds.
mixed() {
  local dir=$1 host_build=$2 chroot_build=$3 tool path
  shift 3
  rm -rf "$dir"
  mkdir -p "$dir"
  for tool in "$host_build"/bin/rsg_* "$host_build"/tests/bin/rsg_*; do ln -s "$tool" "$dir/"; done
  for tool in "$@"; do
    path=$chroot_build/bin/$tool
    [[ -e $path ]] || path=$chroot_build/tests/bin/$tool
    rm -f "$dir/$tool"
    printf '#!/bin/sh\nexec %s in %s "$@"\n' "$checkout/tools/fastdds3/chroot.sh" "$path" > "$dir/$tool"
    chmod +x "$dir/$tool"
  done
}

case ${1:-} in
  setup) setup ;;
  mixed)
    shift
    (($# >= 4)) || die "usage: $0 mixed DIR HOST_BUILD CHROOT_BUILD TOOL..."
    mixed "$@"
    ;;
  run | in)
    setup
    exec_in_namespace "$@"
    ;;
  __mounted)
    shift
    mount_all
    mode=$1
    shift
    if [[ $mode == in ]]; then in_chroot "$@"; else RSG_TRIXIE_ROOT=$root "$@"; fi
    ;;
  *) die "usage: $0 setup | run CMD... | in CMD... | mixed DIR HOST_BUILD CHROOT_BUILD TOOL..." ;;
esac
