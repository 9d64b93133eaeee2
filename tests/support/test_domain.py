#!/usr/bin/env python3
"""DDS domains for tests that run side by side (`ctest -j`), and a wrapper for tests that are scripts.

A test process takes a domain of the pool by holding an exclusive lock (flock) on the domain's file in
LOCK_DIR for as long as it runs; the kernel drops the lock when the process ends, however it ends
(SIGKILL included), so no domain is ever leaked and two running tests never share one, whichever
worktree or ctest run they come from. The scan starts at an offset taken from the pid, so that
successive tests move through the pool rather than reusing the domain the last test just left.

The pool, 20 to 99: a domain's ports (7400 + 250 * domain + ...: 12400 to 32400) stay below Linux's
ephemeral range (32768 and up), so a port the kernel hands out for port 0 (harness.free_udp_port) is
never one a DDS participant of another test binds, and ROS 2's valid domain ids (0 to 101) hold it.
`tests/support/test_domain.hpp` is the same allocator for C++ tests: keep the two in step.

As a command, for tests that are shell scripts:

    test_domain.py [--env NAME] [--port-env NAME]... -- COMMAND [ARG...]

takes a domain, puts it into the environment as NAME (default RSG_TEST_DOMAIN) and execs COMMAND,
which inherits the locked file and so holds the domain until it and its children exit; each
--port-env NAME puts there a port the kernel picked, free for UDP and TCP on 127.0.0.1 (a fixed
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

_held = {}  # domain -> file descriptor holding its lock


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


def test_domain():
    """The DDS domain of this test: the first one the process acquired (acquired on the first call)."""
    return next(iter(_held)) if _held else acquire_domain()


def free_port():
    """A port the kernel picked (port 0) that is free for both UDP and TCP on 127.0.0.1 right now."""
    while True:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
            udp.bind(("127.0.0.1", 0))
            port = udp.getsockname()[1]
            with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as tcp:
                try:
                    tcp.bind(("127.0.0.1", port))
                    return port
                except OSError:
                    continue


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
        os.environ[name] = str(free_port())
    os.execvp(command[0], command)


if __name__ == "__main__":
    sys.exit(main())
