#!/bin/bash
# The image's HEALTHCHECK (docker/Dockerfile): GET /healthz from the gateway's metrics endpoint on
# loopback (the entrypoint passes --metrics 127.0.0.1:$RSG_METRICS_PORT), healthy on 200, which the
# gateway answers while valid frames arrive within the link deadline (503 otherwise: no robot, or
# it stopped; docs/service.md). bash's /dev/tcp, so that the image needs no HTTP client. A container
# of another tool (--entrypoint rsg_echo, ...) runs no gateway and is healthy.
grep -qsx rsg_gateway /proc/[0-9]*/comm || exit 0
exec 3<> "/dev/tcp/127.0.0.1/${RSG_METRICS_PORT:-9470}" || exit 1
printf 'GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n' >&3
read -r -t 2 _ code _ <&3 || exit 1
[[ $code == 200 ]]
