#!/usr/bin/env python3
"""rsg_gateway --check-config (or --check): checks what a start checks, prints what it found and
exits 0 or 2 without starting anything (docs/configuration.md).

"Without starting": the UDP port of --listen and the TCP port of --metrics are held by this test
while the check runs; a start would fail on them (exit 1), the check does not open them.

Run by ctest as tools.check_config (label `cli`); by hand:
    tests/tools/test_check_config.py build/bin/rsg_gateway xml_profiles
Standard library only.
"""

import os
import socket
import subprocess
import sys
import tempfile

failures = []

EXTRA_PROFILE = """<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <profiles>
    <data_writer profile_name="check_config_writer">
      <qos><reliability><kind>BEST_EFFORT</kind></reliability></qos>
    </data_writer>
  </profiles>
</dds>
"""


def check(condition, message):
    if not condition:
        failures.append(message)
        print(f"FAIL: {message}", file=sys.stderr)


def run(gateway, args):
    done = subprocess.run([gateway, *args], capture_output=True, timeout=30, check=False, stdin=subprocess.DEVNULL)
    return done.returncode, done.stdout.decode(errors="replace"), done.stderr.decode(errors="replace")


def main():
    if len(sys.argv) != 3:
        sys.exit(f"usage: {sys.argv[0]} RSG_GATEWAY PROFILES_DIR")
    gateway, profiles_dir = sys.argv[1:]
    with tempfile.TemporaryDirectory() as tmp, \
            socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp, \
            socket.socket(socket.AF_INET, socket.SOCK_STREAM) as tcp:
        udp.bind(("127.0.0.1", 0))
        tcp.bind(("127.0.0.1", 0))
        tcp.listen(1)
        listen = f"127.0.0.1:{udp.getsockname()[1]}"
        metrics = f"127.0.0.1:{tcp.getsockname()[1]}"
        extra = os.path.join(tmp, "extra.xml")
        with open(extra, "w", encoding="utf-8") as out:
            out.write(EXTRA_PROFILE)
        config = os.path.join(tmp, "gateway.yaml")
        with open(config, "w", encoding="utf-8") as out:
            out.write(f"listen: {listen}\nmetrics: {metrics}\npartition: robot1\nlog-level: WARN\n"
                      f"profiles: [{profiles_dir}, {extra}]\nwriter-profile: check_config_writer\n"
                      f"rate-topic: [robot_state_50hz:50]\nstats-file: {tmp}/stats.json\n")

        # A good configuration on ports that are taken: 0, and what it found on stdout.
        status, out, err = run(gateway, ["--config", config, "--check-config"])
        check(status == 0, f"--check-config of a good file: exit {status} ({err.strip()!r})")
        for expected in (f"configuration: {config}", f"ingress: UDP {listen} -> topic 'robot_state'",
                         "rate topic: 'robot_state_50hz'", f"metrics: http://{metrics}/metrics",
                         f"profiles: {profiles_dir}, {extra}", "state writer 'check_config_writer'",
                         "log level: warn", "configuration OK"):
            check(expected in out, f"--check-config stdout lacks {expected!r}: {out!r}")
        status, _, err = run(gateway, ["--config", config])
        check(status == 1, f"a real start on the held ports should fail with 1 (the check bound nothing), got {status}")

        # The same profiles given as repeated flags, and --check as the short name.
        status, out, err = run(gateway, ["--listen", listen, "--profiles", profiles_dir, "--profiles", extra,
                                         "--writer-profile", "check_config_writer", "--check"])
        check(status == 0 and "configuration OK" in out, f"--check with two --profiles: exit {status} ({err.strip()!r})")

        # What is wrong: exit 2, one line naming it, nothing on stdout.
        typo = os.path.join(tmp, "typo.yaml")
        with open(typo, "w", encoding="utf-8") as out:
            out.write(f"listen: {listen}\ndomain: 3\ntopic robot\nexpected-rate: 1000\n")
        for args, expected in (
                (["--config", typo], f"{typo}:3: not a 'key: value' line"),
                (["--listen", listen, "--writer-profile", "nowhere"], "--writer-profile: no data_writer profile named 'nowhere'"),
                (["--listen", listen, "--egress-topic", "cmd", "--send-to", "127.0.0.1:9", "--reader-profile", "nowhere"],
                 "--reader-profile: no data_reader profile named 'nowhere'"),
                (["--listen", listen, "--pcap-ring", "600", "--pcap-dir", tmp, "--expected-rate", "100000"],
                 "--pcap-ring: 600 s at --expected-rate 100000"),
                (["--listen", listen, "--log-level", "verbose"], "--log-level: 'verbose' is not one of"),
                # The reason for exit 2 is written even when the log is off.
                (["--listen", listen, "--log-level", "off", "--writer-profile", "nowhere"],
                 "--writer-profile: no data_writer profile named 'nowhere'"),
                (["--listen", listen, "--stats-file", "/nonexistent/dir/stats.json"], "--stats-file: cannot write"),
                (["--config", os.path.join(tmp, "absent.yaml")], "No such file or directory"),
        ):
            status, out, err = run(gateway, [*args, "--check-config"])
            shown = " ".join(args)
            check(status == 2, f"{shown} --check-config: exit {status}, expected 2 ({err.strip()!r})")
            check(expected in err and err.count("\n") == 1, f"{shown} --check-config: stderr {err!r} lacks {expected!r}")
            check(out == "", f"{shown} --check-config wrote to stdout: {out!r}")
    if failures:
        sys.exit(f"{len(failures)} failed")
    print("--check-config: a good configuration 0 without binding its ports, 8 bad ones 2 with the reason")


if __name__ == "__main__":
    main()
