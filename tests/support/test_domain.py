#!/usr/bin/env python3
"""DDS domains for tests that run side by side (`ctest -j`), and a wrapper for tests that are scripts.

A test process takes a domain of the pool by holding an exclusive lock (flock) on the domain's file in
LOCK_DIR for as long as it runs; the kernel drops the lock when the process ends, however it ends
(SIGKILL included), so no domain is ever leaked and two running tests never share one, whichever
worktree or ctest run they come from. The scan starts at an offset taken from the pid, so that
successive tests move through the pool rather than reusing the domain the last test just left.

The pool, 20 to 99: a domain's ports (7400 + 250 * domain + ...: 12400 to 32400) stay below Linux's
ephemeral range (32768 and up), and ROS 2's valid domain ids (0 to 101) hold it.

The ports a test gives its processes (a gateway's --listen, a metrics or view server) come from a
block of its domain's own, PORTS_PER_DOMAIN from FIRST_PORT (2000 to 7119: below every DDS domain's
ports and below the ephemeral range): test_port(). A port the kernel picks for port 0 is free when
picked, but a socket another process binds to port 0 meanwhile (Fast DDS's output sockets, any
client) can take it before the test's process binds it ("Address already in use", seen under
ctest -j); no other running test and no port-0 socket takes a port of the test's block.
`tests/support/test_domain.hpp` is the same allocator for C++ tests: keep the two in step.

As a command, for tests that are shell scripts:

    test_domain.py [--env NAME] [--port-env NAME]... -- COMMAND [ARG...]

takes a domain, puts it into the environment as NAME (default RSG_TEST_DOMAIN) and execs COMMAND,
which inherits the locked file and so holds the domain until it and its children exit; each
--port-env NAME puts there a port of the domain's block, free for UDP and TCP on 127.0.0.1 (a fixed
or pid-derived port may be one another test holds).
"""
import argparse
import fcntl
import os
import socket
import sys

LOCK_DIR = os.environ.get("RSG_TEST_LOCK_DIR", "/tmp/rsg-test-domains")
FIRST_DOMAIN = 20
LAST_DOMAIN = 99
FIRST_PORT = 2000
PORTS_PER_DOMAIN = 64

_held = {}  # domain -> file descriptor holding its lock
_next_port = {}  # domain -> index in its block of the next port to try


def acquire_domain(inheritable=False):
    """A domain no other running test holds; this process holds it until it exits."""
    os.makedirs(LOCK_DIR, mode=0o1777, exist_ok=True)
    count = LAST_DOMAIN - FIRST_DOMAIN + 1
    start = os.getpid() % count
    for step in range(count):
        domain = FIRST_DOMAIN + (start + step) % count
        if domain in _held:
            continue
        fd = os.open(os.path.join(LOCK_DIR, f"{domain}.lock"), os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            continue
        os.set_inheritable(fd, inheritable)
        _held[domain] = fd
        return domain
    raise RuntimeError(f"all {count} test DDS domains ({FIRST_DOMAIN}-{LAST_DOMAIN}) are held by running "
                       f"tests (locks in {LOCK_DIR}): run fewer tests at once")


def release_domain(domain):
    """Gives back a domain this process acquired (a benchmark that wants a fresh domain per point)."""
    os.close(_held.pop(domain))


def others_running():
    """Whether a test other than this process holds a domain of the pool (is running now)."""
    for domain in range(FIRST_DOMAIN, LAST_DOMAIN + 1):
        if domain in _held:
            continue
        try:
            fd = os.open(os.path.join(LOCK_DIR, f"{domain}.lock"), os.O_RDWR | os.O_CLOEXEC)
        except FileNotFoundError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            fcntl.flock(fd, fcntl.LOCK_UN)
        except BlockingIOError:
            return True
        finally:
            os.close(fd)
    return False


def test_domain():
    """The DDS domain of this test: the first one the process acquired (acquired on the first call)."""
    return next(iter(_held)) if _held else acquire_domain()


def _bindable(port):
    """Whether both UDP and TCP can bind `port` on 127.0.0.1 right now."""
    try:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp, \
                socket.socket(socket.AF_INET, socket.SOCK_STREAM) as tcp:
            udp.bind(("127.0.0.1", port))
            tcp.bind(("127.0.0.1", port))
            return True
    except OSError:
        return False


def test_port():
    """A port of this test's block, free for UDP and TCP on 127.0.0.1 right now; each call the next
    one (two processes of one test start at different places of the block: the pid)."""
    domain = test_domain()
    base = FIRST_PORT + (domain - FIRST_DOMAIN) * PORTS_PER_DOMAIN
    start = _next_port.get(domain, os.getpid() % PORTS_PER_DOMAIN)
    for step in range(PORTS_PER_DOMAIN):
        index = (start + step) % PORTS_PER_DOMAIN
        if _bindable(base + index):
            _next_port[domain] = index + 1
            return base + index
    raise RuntimeError(f"no free port in domain {domain}'s block {base}-{base + PORTS_PER_DOMAIN - 1} on 127.0.0.1")


def main():
    parser = argparse.ArgumentParser(description="Runs COMMAND with a DDS domain of its own in the environment.")
    parser.add_argument("--env", default="RSG_TEST_DOMAIN", help="the variable that names the domain")
    parser.add_argument("--port-env", action="append", default=[], help="a variable to set to a free port")
    parser.add_argument("command", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("no COMMAND")
    domain = acquire_domain(inheritable=True)
    os.environ[args.env] = str(domain)
    for name in args.port_env:
        os.environ[name] = str(test_port())
    os.execvp(command[0], command)


if __name__ == "__main__":
    sys.exit(main())
