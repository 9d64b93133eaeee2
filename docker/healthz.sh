#!/bin/bash
# The image's HEALTHCHECK (docker/Dockerfile): GET /livez from the gateway's metrics endpoint on
# loopback (the entrypoint passes --metrics 127.0.0.1:$RSG_METRICS_PORT), healthy on 200, which the
# gateway answers while its loop runs, robot or no robot (503 when the loop is stuck; a frozen
# process does not answer within the 2 s below). Whether the robot streams is /readyz's, not a
# reason to restart the container (docs/service.md). bash's /dev/tcp, so that the image needs no
# HTTP client. A container of another tool (--entrypoint rsg_echo, ...) runs no gateway and is healthy.
grep -qsx rsg_gateway /proc/[0-9]*/comm || exit 0
exec 3<> "/dev/tcp/127.0.0.1/${RSG_METRICS_PORT:-9470}" || exit 1
printf 'GET /livez HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n' >&3
read -r -t 2 _ code _ <&3 || exit 1
[[ $code == 200 ]]
