#!/bin/sh
# Runs a test command with a /dev/shm of its own: an empty tmpfs in a private mount namespace.
#
#   tests/support/private_shm.sh ctest -L unit ...
#
# Why: Fast DDS keeps its shared-memory transport's ports (fastrtps_port<N>, named by port number,
# so by domain) and data-sharing segments in /dev/shm, and a process killed by a test leaves them
# there. A Fast DDS 2.9.1 participant that opens a port file a build with another layout left
# behind aborts on a Boost.Interprocess assertion (segment_manager.hpp, priv_generic_find): seen in
# CI, where a port of domain 73 left by another suite's build aborted every unit test that drew
# domain 73. With a /dev/shm of their own, the tests neither meet another run's files nor leave
# theirs on the host. rsg's own participants use UDP only (xml_profiles/rsg.xml); the unit tests'
# default-QoS participants do use the SHM transport.
#
# Everything the command starts shares that /dev/shm (the Fast DDS 3 chroot binds it too). The
# suites with containers (make test-image, test-service) do not use it: their containers share
# the host's /dev/shm on purpose. Needs root (unshare -m); anyone else runs the command as it is,
# with the host's /dev/shm, and is told so.
set -eu
if [ -n "${RSG_PRIVATE_SHM:-}" ]; then exec "$@"; fi
if [ "$(id -u)" -ne 0 ]; then
  echo "private_shm.sh: not root: the tests share the host's /dev/shm (a leftover Fast DDS file of another build can abort them)" >&2
  exec "$@"
fi
exec unshare --mount --propagation private -- sh -c '
  mount -t tmpfs -o mode=1777,size=50% rsg-test-shm /dev/shm || exit 1
  RSG_PRIVATE_SHM=1 exec "$@"' private_shm.sh "$@"
