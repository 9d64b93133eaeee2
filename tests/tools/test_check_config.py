#!/usr/bin/env python3
"""rsg_gateway --check-config (or --check): checks what a start checks, prints what it found and
exits 0 or 2 without starting anything (docs/configuration.md).

"Without starting": the UDP port of --listen and the TCP port of --metrics are held by this test
while the check runs; a start would fail on them (exit 1), the check does not open them.

Durations Fast DDS cannot represent (CVE-2025-63829): a profile file with <nanosec> 10^9 or more,
or a negative <sec>, is refused by --check-config and by a start, exit 2 with the file, the line and
the element, and by every tool that loads profiles (rsg_echo here). The control: a plain Fast DDS
participant (rsg_fastdds_flaws_probe, none of rsg's checks) made from such a profile, which on Fast
DDS 2.9 never returns from create_participant and keeps a core busy; killed after a few seconds.

Run by ctest as tools.check_config (label `cli`); by hand:
    tests/tools/test_check_config.py build/bin/rsg_gateway xml_profiles build/tests/bin/rsg_fastdds_flaws_probe
Standard library only (and tests/support's test_domain, for the control's DDS domain).
"""

import os
import socket
import subprocess
import sys
import tempfile
import time

from test_domain import acquire_domain

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


# A participant whose lease duration's nanoseconds are a whole second: Fast DDS 2.9.1 loads it, then
# loops in Time_t::fraction() when it serializes the duration into the participant's announcement.
SPINNING_PROFILE = """<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <profiles>
    <participant profile_name="lease_nanosec">
      <rtps>
        <builtin>
          <discovery_config>
            <leaseDuration>
              <sec>20</sec>
              <nanosec>1000000000</nanosec>
            </leaseDuration>
          </discovery_config>
        </builtin>
      </rtps>
    </participant>
  </profiles>
</dds>
"""
SPINNING_LINE = 10  # of <nanosec> above

# Other durations Fast DDS cannot represent, in a writer's QoS: (the duration's children, the part
# refused, what the error says).
BAD_DURATIONS = [
    ("<sec>0</sec><nanosec>4000000000</nanosec>", "<nanosec>4000000000</nanosec>", "nanoseconds must be"),
    ("<nanosec>5</nanosec><nanosec>1000000001</nanosec>", "<nanosec>1000000001</nanosec>", "nanoseconds must be"),
    ("<sec>-1</sec>", "<sec>-1</sec>", "seconds must be"),
    ("<sec>2147483648</sec>", "<sec>2147483648</sec>", "seconds must be"),
    ("<sec>1</sec><nanosec>1e9</nanosec>", "<nanosec>1e9</nanosec>", "not a whole number"),
]
WRITER_PROFILE = """<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <profiles>
    <data_writer profile_name="bad_duration_writer">
      <qos><reliability><kind>RELIABLE</kind><max_blocking_time>{duration}</max_blocking_time></reliability></qos>
    </data_writer>
  </profiles>
</dds>
"""
# Durations Fast DDS can represent: accepted.
GOOD_DURATIONS = ["<sec>1</sec><nanosec>999999999</nanosec>", "<sec>DURATION_INFINITY</sec>",
                  "DURATION_INFINITY", "<sec>2147483647</sec><nanosec>4294967295</nanosec>"]
CLOCK_TICKS = os.sysconf("SC_CLK_TCK")
CONTROL_WATCH_S = 3.0


def cpu_s(pid):
    with open(f"/proc/{pid}/stat", encoding="ascii") as stat:
        fields = stat.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / CLOCK_TICKS


def runnable_s(tid):
    """Seconds thread `tid` has been on a core or waiting for one (/proc/TID/schedstat): a thread that
    spins is runnable all the time, however little of a core a loaded machine gives it."""
    with open(f"/proc/{tid}/task/{tid}/schedstat", encoding="ascii") as schedstat:
        on_cpu, waiting = schedstat.read().split()[:2]
    return (int(on_cpu) + int(waiting)) / 1e9


def spinning_control(probe, profile):
    """A plain Fast DDS participant made from `profile`: whether create_participant returned within
    CONTROL_WATCH_S, the share of that time its main thread (the one in create_participant) was
    runnable, and the share of a core the probe used. The probe is killed (SIGKILL, by its own pid)
    whatever it did."""
    domain = acquire_domain()
    with tempfile.TemporaryFile() as out:
        process = subprocess.Popen([probe, "--domain", str(domain), "--profiles", profile, "--participant-profile",
                                    "lease_nanosec", "--duration", "1"], stdout=out, stderr=subprocess.STDOUT,
                                   stdin=subprocess.DEVNULL)
        try:
            start, cpu0, runnable0 = time.monotonic(), cpu_s(process.pid), runnable_s(process.pid)
            time.sleep(CONTROL_WATCH_S)
            cpu = runnable = 0.0
            if process.poll() is None:
                elapsed = time.monotonic() - start
                cpu = (cpu_s(process.pid) - cpu0) / elapsed * 100
                runnable = (runnable_s(process.pid) - runnable0) / elapsed * 100
        finally:
            process.kill()
            process.wait()
        out.seek(0)
        said = out.read().decode(errors="replace")
    version = next((line.split()[1] for line in said.splitlines() if line.startswith("fastdds ")), "?")
    return version, "participant created" in said, runnable, cpu


def check(condition, message):
    if not condition:
        failures.append(message)
        print(f"FAIL: {message}", file=sys.stderr)


def run(gateway, args, timeout_s=30):
    done = subprocess.run([gateway, *args], capture_output=True, timeout=timeout_s, check=False,
                          stdin=subprocess.DEVNULL)
    return done.returncode, done.stdout.decode(errors="replace"), done.stderr.decode(errors="replace")


def main():
    if len(sys.argv) != 4:
        sys.exit(f"usage: {sys.argv[0]} RSG_GATEWAY PROFILES_DIR RSG_FASTDDS_FLAWS_PROBE")
    gateway, profiles_dir, probe = sys.argv[1:]
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

        check_durations(gateway, profiles_dir, probe, listen, tmp)
    if failures:
        sys.exit(f"{len(failures)} failed")
    print("--check-config: a good configuration 0 without binding its ports, 8 bad ones 2 with the reason; "
          f"{1 + len(BAD_DURATIONS)} durations Fast DDS cannot represent refused, {len(GOOD_DURATIONS)} good ones taken")


def check_durations(gateway, profiles_dir, probe, listen, tmp):
    """CVE-2025-63829: the profile Fast DDS loops on, refused by --check-config, a start and rsg_echo;
    the control shows what Fast DDS itself does with it."""
    spinning = os.path.join(tmp, "lease_nanosec.xml")
    with open(spinning, "w", encoding="utf-8") as out:
        out.write(SPINNING_PROFILE)
    expected = (f"{spinning}:{SPINNING_LINE}: <leaseDuration> <nanosec>1000000000</nanosec>: nanoseconds must be "
                "from 0 to 999999999")
    echo = os.path.join(os.path.dirname(gateway), "rsg_echo")
    for args in (["--listen", listen, "--profiles", profiles_dir, "--profiles", spinning, "--check-config"],
                 ["--listen", listen, "--profiles", profiles_dir, "--profiles", spinning]):
        shown = " ".join(args)
        try:
            status, out, err = run(gateway, args, timeout_s=15)
        except subprocess.TimeoutExpired:
            check(False, f"rsg_gateway {shown}: still running after 15 s (killed): the profile reached Fast DDS")
            continue
        check(status == 2, f"rsg_gateway {shown}: exit {status}, expected 2 ({err.strip()!r})")
        check(expected in err and err.count("\n") == 1, f"rsg_gateway {shown}: stderr {err!r} lacks {expected!r}")
        check(out == "", f"rsg_gateway {shown} wrote to stdout: {out!r}")
    try:
        status, _, err = run(echo, ["--profiles", profiles_dir, "--profiles", spinning, "--timeout", "1"], timeout_s=15)
        check(status == 2 and expected in err, f"rsg_echo --profiles {spinning}: exit {status} ({err.strip()!r})")
    except subprocess.TimeoutExpired:
        check(False, f"rsg_echo --profiles {spinning}: still running after 15 s (killed): the profile reached Fast DDS")

    for index, (duration, part, what) in enumerate(BAD_DURATIONS):
        path = os.path.join(tmp, f"bad_duration{index}.xml")
        with open(path, "w", encoding="utf-8") as out:
            out.write(WRITER_PROFILE.format(duration=duration))
        status, out, err = run(gateway, ["--listen", listen, "--profiles", profiles_dir, "--profiles", path,
                                         "--writer-profile", "bad_duration_writer", "--check-config"])
        said = f"{path}:5: <max_blocking_time> {part}: {what}"
        check(status == 2 and said in err and err.count("\n") == 1,
              f"--check-config of a max_blocking_time of {duration}: exit {status}, stderr {err!r} lacks {said!r}")
    for index, duration in enumerate(GOOD_DURATIONS):
        path = os.path.join(tmp, f"good_duration{index}.xml")
        with open(path, "w", encoding="utf-8") as out:
            out.write(WRITER_PROFILE.format(duration=duration))
        status, out, err = run(gateway, ["--listen", listen, "--profiles", profiles_dir, "--profiles", path,
                                         "--writer-profile", "bad_duration_writer", "--check-config"])
        check(status == 0 and "configuration OK" in out,
              f"--check-config of a max_blocking_time of {duration}: exit {status} ({err.strip()!r})")

    # The control: Fast DDS itself on the profile rsg refuses.
    version, created, runnable, cpu = spinning_control(probe, spinning)
    if created:
        print(f"[check_config] control, Fast DDS {version}: a participant made from {os.path.basename(spinning)} "
              "was created: no effect here (this Fast DDS has the fix of CVE-2025-63829)")
    else:
        print(f"[check_config] control, Fast DDS {version}: create_participant had not returned after "
              f"{CONTROL_WATCH_S:.0f} s, its thread runnable {runnable:.0f} % of the time ({cpu:.0f} % of a core); "
              "killed")
    if version.startswith("2.9."):
        # Not created (a participant is made in about 0.1 s) and spinning: a thread that waits for
        # something is runnable about 0 % of the time.
        check(not created and runnable >= 80,
              f"the control: Fast DDS {version} did not loop on <nanosec>1000000000</nanosec> (created {created}, "
              f"runnable {runnable:.0f} %): the check no longer shows what it says")


if __name__ == "__main__":
    main()
