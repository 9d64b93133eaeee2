# Sourced by docker/build-image.sh and tests/image/run.sh: picks the container engine.
# Sets ENGINE (the command, an array) and ENGINE_NAME (docker or podman).
#
# Docker when its engine answers (`docker info`: a docker client alone is not an engine), else
# podman with this repository's settings: docker/containers.conf through CONTAINERS_CONF (no change
# under /etc) and runc as the OCI runtime (crun refuses hosts with hybrid cgroups). RSG_ENGINE=docker
# or RSG_ENGINE=podman forces one.
rsg_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
if [[ "${RSG_ENGINE:-}" != podman ]] && command -v docker > /dev/null && docker info > /dev/null 2>&1; then
  ENGINE=(docker)
  ENGINE_NAME=docker
elif [[ "${RSG_ENGINE:-}" != docker ]] && command -v podman > /dev/null; then
  export CONTAINERS_CONF="$rsg_root/docker/containers.conf"
  ENGINE=(podman --runtime runc)
  ENGINE_NAME=podman
else
  echo "no container engine: neither a Docker engine that answers \`docker info\` nor podman" \
       "(\`make deps\` installs podman)" >&2
  exit 1
fi
