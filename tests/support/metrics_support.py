"""What the metrics tests share: a free TCP port, plain HTTP GETs, the exposition text parsed, and
the gateway started with --metrics."""

import http.client
import re
import shutil

from harness import TestFailure, check, free_tcp_port, free_udp_port, wait_for  # noqa: F401 (free_tcp_port re-exported)

# A sample line of the text exposition format: name, optional {labels}, value (no timestamps: rsg writes none).
_SAMPLE = re.compile(r'^([a-zA-Z_:][a-zA-Z0-9_:]*)(\{(.*)\})? (\S+)$')
_LABEL = re.compile(r'([a-zA-Z_][a-zA-Z0-9_]*)="((?:[^"\\]|\\.)*)"')


def http_get(port, path, timeout_s=5.0):
    """(status, body) of GET http://127.0.0.1:port/path, or None when nothing answers."""
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout_s)
    try:
        connection.request("GET", path)
        response = connection.getresponse()
        return response.status, response.read().decode()
    except OSError:
        return None
    finally:
        connection.close()


def parse_samples(text):
    """[(name, {label: value}, float value)] of every sample line."""
    samples = []
    for line in text.splitlines():
        if not line or line.startswith("#"):
            continue
        match = _SAMPLE.match(line)
        check(match is not None, f"not a sample line of the exposition format: {line!r}")
        labels = dict(_LABEL.findall(match.group(3) or ""))
        samples.append((match.group(1), labels, float(match.group(4))))
    return samples


def value_of(samples, name, **labels):
    """The value of the one series `name` whose labels include `labels`."""
    found = [value for n, l, value in samples if n == name and all(l.get(k) == v for k, v in labels.items())]
    check(len(found) == 1, f"{len(found)} series {name}{labels} in the scrape")
    return found[0]


def require_tool(name):
    """The path of a program the test cannot run without: a missing one fails the test (never skips)."""
    path = shutil.which(name)
    if path is None:
        raise TestFailure(f"{name} is not installed: apt-get install prometheus (make deps installs it, "
                          f"docker/packages/test.txt)")
    return path


def start_gateway(h, label, *flags, rate="500"):
    """A gateway with ingress on a free UDP port and metrics on a free TCP port, once /metrics answers.
    Returns (process, stats file, UDP port, metrics port)."""
    udp, metrics = free_udp_port(), free_tcp_port()
    gateway, stats = h.gateway(label, "--listen", f"127.0.0.1:{udp}", "--expected-rate", rate,
                               "--metrics", f"127.0.0.1:{metrics}", *flags)
    wait_for(lambda: gateway.poll() is not None or http_get(metrics, "/metrics"), f"{label}'s /metrics to answer")
    check(gateway.poll() is None, f"{label} exited {gateway.poll()} at start")
    return gateway, stats, udp, metrics
