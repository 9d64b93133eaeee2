#!/usr/bin/env python3
"""rsg_gateway --check-config (or --check): checks what a start checks, prints what it found and
exits 0, 2 (the configuration) or 1 (this host refuses it) without starting anything
(docs/configuration.md). Every case is run as a real start too, which must fail (or pass) the
same way, with the same line:

- the ports: --listen's UDP port or --metrics' TCP port held by this test, an address not on this
  host: exit 1, "cannot bind UDP ..." / "--metrics: cannot listen on ...", as the start;
- the files the participant profile names (DDS Security's): missing, a directory, not PEM: exit 2
  naming the property and the file, as the start (Fast DDS's own refusal names neither);
- --config naming a directory: exit 2 "is a directory" (it read as an empty configuration);
- the directories the systemd unit creates at its start (/run/rsg/NAME, /var/lib/rsg/NAME) need
  not exist for the check, which says the unit creates them; a start outside the unit fails on
  them, naming RuntimeDirectory= for the stats file and StateDirectory= for pcap-dir;
- --instance NAME: partition, stats file and pcap-dir from NAME unless the file sets them.

The good configuration's ports are free (this test's block, tests/support/test_domain.py) and the
check closes them again: a start right after it binds them.

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
import secrets
import socket
import subprocess
import sys
import tempfile
import time

from test_domain import acquire_domain, test_domain, test_port

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


SECURE_PROFILE = """<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <profiles>
    <participant profile_name="check_secure">
      <rtps>
        <propertiesPolicy>
          <properties>
            <property><name>dds.sec.auth.plugin</name><value>builtin.PKI-DH</value></property>
            <property><name>dds.sec.auth.builtin.PKI-DH.identity_ca</name><value>file://{ca}</value></property>
          </properties>
        </propertiesPolicy>
      </rtps>
    </participant>
  </profiles>
</dds>
"""


def expect_both(gateway, args, status, expected, shown):
    """--check-config and a real start of `args` both exit `status` with `expected` on stderr."""
    for mode in ("check", "start"):
        argv = [*args, "--check-config"] if mode == "check" else args
        code, out, err = run(gateway, argv)
        check(code == status, f"{shown} ({mode}): exit {code}, expected {status} ({err.strip()!r})")
        check(expected in err, f"{shown} ({mode}): stderr {err!r} lacks {expected!r}")
        if mode == "check":
            check(out == "", f"{shown} --check-config wrote to stdout: {out!r}")


def main():
    if len(sys.argv) != 4:
        sys.exit(f"usage: {sys.argv[0]} RSG_GATEWAY PROFILES_DIR RSG_FASTDDS_FLAWS_PROBE")
    gateway, profiles_dir, flaws_probe = sys.argv[1:]
    with tempfile.TemporaryDirectory() as tmp:
        listen = f"127.0.0.1:{test_port()}"
        metrics = f"127.0.0.1:{test_port()}"
        extra = os.path.join(tmp, "extra.xml")
        with open(extra, "w", encoding="utf-8") as out:
            out.write(EXTRA_PROFILE)
        config = os.path.join(tmp, "gateway.yaml")
        with open(config, "w", encoding="utf-8") as out:
            out.write(f"listen: {listen}\nmetrics: {metrics}\npartition: robot1\nlog-level: WARN\n"
                      f"domain: {test_domain()}\n"
                      f"profiles: [{profiles_dir}, {extra}]\nwriter-profile: check_config_writer\n"
                      f"rate-topic: [robot_state_50hz:50]\nstats-file: {tmp}/stats.json\n")

        # A good configuration on free ports: 0, what it found on stdout, and the ports free again.
        status, out, err = run(gateway, ["--config", config, "--check-config"])
        check(status == 0, f"--check-config of a good file: exit {status} ({err.strip()!r})")
        for expected in (f"configuration: {config}", f"ingress: UDP {listen} -> topic 'robot_state'",
                         "rate topic: 'robot_state_50hz'", f"metrics: http://{metrics}/metrics",
                         f"profiles: {profiles_dir}, {extra}", "state writer 'check_config_writer'",
                         "log level: warn", "configuration OK"):
            check(expected in out, f"--check-config stdout lacks {expected!r}: {out!r}")
        for kind, port in ((socket.SOCK_DGRAM, listen), (socket.SOCK_STREAM, metrics)):
            with socket.socket(socket.AF_INET, kind) as probe:
                probe.bind(("127.0.0.1", int(port.rsplit(":", 1)[1])))  # raises when the check kept it

        # The same profiles given as repeated flags, and --check as the short name.
        status, out, err = run(gateway, ["--listen", listen, "--profiles", profiles_dir, "--profiles", extra,
                                         "--writer-profile", "check_config_writer", "--check"])
        check(status == 0 and "configuration OK" in out, f"--check with two --profiles: exit {status} ({err.strip()!r})")

        # The running gateway of this very file holds its ports (the operator checks before a
        # restart): not a failure, said.
        running = subprocess.Popen([gateway, "--config", config], stdin=subprocess.DEVNULL,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        try:
            for _ in range(300):
                if os.path.exists(os.path.join(tmp, "stats.json")) or running.poll() is not None:
                    break
                time.sleep(0.1)
            if running.poll() is not None:
                check(False, f"the gateway of {config} exited {running.returncode}: {running.stderr.read()!r}")
            check(os.path.exists(os.path.join(tmp, "stats.json")), f"the gateway of {config} wrote no stats file "
                  f"in 30 s: {os.listdir(tmp)}")
            status, out, err = run(gateway, ["--config", config, "--check-config"])
            check(status == 0 and f"UDP {listen} is held by the running rsg_gateway of this configuration (pid "
                  f"{running.pid})" in out and f"TCP {metrics} is held by the running rsg_gateway" in out,
                  f"--check-config beside its own running gateway: exit {status}: {out!r} {err!r}")
        finally:
            running.terminate()
            running.wait(timeout=30)

        # Ports a start cannot have: exit 1 for the check as for the start, with the start's line
        # (and, for the check, who holds the port).
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
            udp.bind(("127.0.0.1", int(listen.rsplit(":", 1)[1])))
            expect_both(gateway, ["--listen", listen], 1, f"cannot bind UDP {listen}: Address already in use",
                        "--listen on a port in use")
            status, _, err = run(gateway, ["--listen", listen, "--check-config"])
            check(f"(held by pid {os.getpid()}: " in err, f"the check does not name this test as the holder: {err!r}")
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as tcp:
            tcp.bind(("127.0.0.1", int(metrics.rsplit(":", 1)[1])))
            tcp.listen(1)
            expect_both(gateway, ["--listen", listen, "--metrics", metrics], 1,
                        f"--metrics: cannot listen on {metrics}: Address already in use", "--metrics on a port in use")
        # 192.0.2.1 (TEST-NET-1) is on no host.
        expect_both(gateway, ["--listen", "192.0.2.1:5000"], 1, "cannot bind UDP 192.0.2.1:5000: Cannot assign requested address",
                    "--listen on an address not on this host")

        # The files the participant profile names: missing, a directory, not PEM.
        not_pem = os.path.join(tmp, "ca.pem")
        with open(not_pem, "w", encoding="utf-8") as out:
            out.write("not a certificate\n")
        for ca, expected in ((os.path.join(tmp, "absent.pem"), "No such file or directory"),
                             (tmp, "Is a directory"), (not_pem, "not PEM")):
            secure = os.path.join(tmp, "secure.xml")
            with open(secure, "w", encoding="utf-8") as out:
                out.write(SECURE_PROFILE.format(ca=ca))
            expect_both(gateway, ["--listen", listen, "--profiles", profiles_dir, "--profiles", secure,
                                  "--participant-profile", "check_secure"], 2,
                        f"participant profile 'check_secure', property dds.sec.auth.builtin.PKI-DH.identity_ca: "
                        f"'{ca}': {expected}", f"identity_ca {ca}")

        # --config naming a directory: refused, not read as an empty configuration.
        expect_both(gateway, ["--listen", listen, "--config", tmp], 2, f"--config: '{tmp}' is a directory",
                    "--config DIR")

        # The unit's directories: not required by the check, named by the start's hint.
        name = f"rsg-check-{secrets.token_hex(4)}"
        unit_config = os.path.join(tmp, "unit.yaml")
        with open(unit_config, "w", encoding="utf-8") as out:
            out.write(f"listen: {listen}\nstats-file: /run/rsg/{name}/stats.json\npcap-ring: 1\n"
                      f"pcap-dir: /var/lib/rsg/{name}\n")
        status, out, err = run(gateway, ["--config", unit_config, "--check-config"])
        check(status == 0, f"--check-config with the unit's directories absent: exit {status} ({err.strip()!r})")
        for expected in (f"/run/rsg/{name} does not exist now: the unit creates it with RuntimeDirectory=",
                         f"/var/lib/rsg/{name} does not exist now: the unit creates it with StateDirectory="):
            check(expected in out, f"--check-config stdout lacks {expected!r}: {out!r}")
        status, _, err = run(gateway, ["--config", unit_config])
        check(status == 2 and "--stats-file: cannot write" in err and "RuntimeDirectory=" in err,
              f"a start outside the unit without /run/rsg/{name}: exit {status} ({err.strip()!r})")
        status, _, err = run(gateway, ["--config", unit_config, "--stats-file", f"{tmp}/stats.json"])
        check(status == 2 and "--pcap-dir: cannot write" in err and "StateDirectory=" in err
              and "RuntimeDirectory=" not in err,
              f"a start outside the unit without /var/lib/rsg/{name}: exit {status} ({err.strip()!r})")
        status, _, err = run(gateway, ["--listen", listen, "--pcap-ring", "1", "--pcap-dir", "/nonexistent/dir",
                                       "--check-config"])
        check(status == 2 and "e.g. StateDirectory= under systemd" in err,
              f"a pcap-dir no unit creates: exit {status} ({err.strip()!r})")

        # --instance: the unit's defaults under what the file sets.
        copied = os.path.join(tmp, "robot2.yaml")
        with open(copied, "w", encoding="utf-8") as out:
            out.write(f"listen: {listen}\npcap-ring: 1\n")
        status, out, err = run(gateway, ["--config", copied, "--instance", name, "--check-config"])
        check(status == 0, f"--instance {name}: exit {status} ({err.strip()!r})")
        for expected in (f"partition '{name}'", f"stats file: /run/rsg/{name}/stats.json",
                         f"into /var/lib/rsg/{name}"):
            check(expected in out, f"--instance {name}: stdout lacks {expected!r}: {out!r}")
        status, out, err = run(gateway, ["--config", config, "--instance", name, "--check-config"])
        check(status == 0 and "partition 'robot1'" in out and f"stats file: {tmp}/stats.json" in out,
              f"--instance under a file that sets partition and stats-file: exit {status}: {out!r} {err!r}")
        status, _, err = run(gateway, ["--config", copied, "--instance", "../etc", "--check-config"])
        check(status == 2 and "--instance: '../etc' cannot name a directory" in err, f"--instance ../etc: {status} {err!r}")

        # What is wrong: exit 2, one line naming it, nothing on stdout.
        typo = os.path.join(tmp, "typo.yaml")
        with open(typo, "w", encoding="utf-8") as out:
            out.write(f"listen: {listen}\ndomain: 3\ntopic robot\nexpected-rate: 1000\n")
        last = os.path.join(tmp, "last.yaml")
        with open(last, "w", encoding="utf-8") as out:
            out.write(f"listen: {listen}\ndomain: 3\ntopic robot\n")
        for args, expected in (
                (["--config", typo], f"{typo}:3: not a 'key: value' line"),
                # The colon-less line last: the same hint, not the list of every key.
                (["--config", last], f"{last}:3: not a 'key: value' line (a missing ':' after 'topic'?)"),
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

        check_durations(gateway, profiles_dir, flaws_probe, listen, tmp)
    if failures:
        sys.exit(f"{len(failures)} failed")
    print("--check-config: a good configuration 0 with its ports free after, ports a start cannot have 1, "
          "missing security files 2, a directory 2, the unit's directories not required, bad values 2 "
          "with the reason; each as a real start;"
          f" {1 + len(BAD_DURATIONS)} durations Fast DDS cannot represent refused, {len(GOOD_DURATIONS)} good ones taken")


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
