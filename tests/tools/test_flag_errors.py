#!/usr/bin/env python3
"""Every flag of every rsg executable refuses a bad value the same way: exit status 2, nothing on
stdout, and a message on stderr, "<tool>: ...", that names the flag (CONTRIBUTING.md, "Errors").
No flag is used before it is checked: a value that reaches a library unchecked (a log level that
spdlog maps to "off", a negative count that wraps around) fails here.

The flags are read from each executable's --help (and each subcommand's), so a new flag fails
this test until BAD_VALUES says how to get it wrong. A flag that takes no value (--help,
--version) has nothing to check.

Run by ctest as tools.flag_errors (label `cli`); by hand:
    tests/tools/test_flag_errors.py build/bin [build/tests/bin]
(rsg_wireshark_lua, which is not installed, is in build/tests/bin: CONTRIBUTING.md, "Build tree").
Standard library only.
"""

import os
import re
import subprocess
import sys
import tempfile

MISSING = "/nonexistent/rsg-flag-errors-input"
NO_DIR = "/nonexistent/rsg-flag-errors-dir"
BAD_HOST_PORT = "nohostport"
CONTROL = "a\nb"  # a name with a control character
NO_VALUE = {"--help", "--version"}

# The arguments of a run whose flags are all good (each case adds its own); {mcap} and {pcap} are
# files the test makes first.
BASE = {
    "rsg_gateway": ["--listen", "127.0.0.1:0"],
    "rsg_echo": ["--timeout", "0.5"],
    "rsg_record": ["--out", "{tmp}/out.mcap", "--duration", "0.2"],
    "rsg_replay": ["{mcap}"],
    "rsg_sim": ["--to", "127.0.0.1:9", "--count", "1"],
    "rsg_view": ["--listen", "127.0.0.1:0"],
    "rsg_frame decode": ["{tmp}/empty"],
    "rsg_frame encode": ["{tmp}/empty"],
    "rsg_frame request": ["--groups", "1"],
    "rsg_wireshark_lua": [],
}

# Shared by the programs that read what the gateway publishes (src/app/monitor_options.hpp and
# profile_options.hpp).
DDS_READER = {
    "--domain": ["--domain", "300"],
    "--topic": ["--topic", ""],
    "--partition": ["--partition", CONTROL],
    "--view": ["--view", "view_nonexistent"],
    "--qos": ["--qos", "qos_nonexistent"],
    "--profiles": ["--profiles", MISSING],
    "--participant-profile": ["--participant-profile", "participant_nonexistent"],
    "--discovery-server": ["--discovery-server", "x@@y"],
    "--peer": ["--peer", "host:70000"],
}

# For each program, each flag: arguments with a bad value for it (on top of BASE).
BAD_VALUES = {
    "rsg_gateway": {
        "--config": ["--config", MISSING],
        "--check-config": ["--check-config=maybe"],
        "--instance": ["--instance", "../etc"],
        "--listen": ["--listen", BAD_HOST_PORT],
        "--allow-from": ["--allow-from", "10.0.0.0/40"],
        "--topic": ["--topic", ""],
        "--domain": ["--domain", "300"],
        "--partition": ["--partition", CONTROL],
        "--receive-buffer": ["--receive-buffer", "-1"],
        "--rate-topic": ["--rate-topic", "slow"],
        "--egress-topic": ["--egress-topic", "cmd"],  # without --send-to
        "--egress-rate": ["--egress-rate", "-1"],
        "--send-to": ["--send-to", "127.0.0.1:0"],
        "--robot": ["--robot", BAD_HOST_PORT, "--request-groups", "1"],
        "--request-groups": ["--request-groups", "6"],
        "--request-fields": ["--request-fields", "qq"],
        "--status-topic": ["--status-topic", ""],
        "--expected-rate": ["--expected-rate", "0"],
        "--restart-threshold-ms": ["--restart-threshold-ms", "0"],
        "--stats-file": ["--stats-file", NO_DIR + "/stats.json"],
        "--metrics": ["--metrics", BAD_HOST_PORT],
        "--name": ["--name", CONTROL],
        "--pcap-ring": ["--pcap-ring", "601", "--pcap-dir", "/tmp"],
        "--pcap-dir": ["--pcap-ring", "1", "--pcap-dir", NO_DIR],
        "--log-level": ["--log-level", "verbose"],
        "--log-format": ["--log-format", "xml"],
        "--metrics-max-connections": ["--metrics-max-connections", "0"],
        "--metrics-max-connections-per-client": ["--metrics-max-connections-per-client", "0"],
        "--metrics-header-timeout-ms": ["--metrics-header-timeout-ms", "1"],
        "--metrics-idle-timeout-ms": ["--metrics-idle-timeout-ms", "1"],
        "--pcap-min-interval": ["--pcap-min-interval", "-1"],
        "--pcap-max-files": ["--pcap-max-files", "0"],
        "--pcap-max-mb": ["--pcap-max-mb", "0"],
        "--pcap-all-sources": ["--pcap-all-sources=maybe"],
        "--reload-widens-access": ["--reload-widens-access=maybe"],
        "--rt-priority": ["--rt-priority", "100"],
        "--cpu": ["--cpu", "-2"],
        "--ros2": ["--ros2=maybe"],
        "--ros2-namespace": ["--ros2", "--ros2-namespace", "no space"],
        "--joint-states": ["--joint-states", "0"],
        "--joint-names": ["--joint-names", "a,b"],
        "--tf": ["--tf", "every:0"],
        "--base-frame": ["--base-frame", "/world"],
        "--ee-frame": ["--ee-frame", ""],
        "--external-wrench": ["--external-wrench", "fast"],
        "--wrench-frame": ["--wrench-frame", "/world"],
        "--profiles": ["--profiles", MISSING],
        "--participant-profile": ["--participant-profile", "participant_nonexistent"],
        "--writer-profile": ["--writer-profile", "writer_nonexistent", "--check-config"],
        "--reader-profile": ["--reader-profile", "reader_nonexistent", "--egress-topic", "cmd", "--send-to",
                             "127.0.0.1:9", "--check-config"],
        "--status-profile": ["--status-profile", "writer_nonexistent", "--check-config"],
        "--data-sharing": ["--data-sharing", "sometimes"],
        "--discovery-server": ["--discovery-server", "x@@y"],
        "--peer": ["--peer", "host:70000"],
    },
    "rsg_echo": {
        **DDS_READER,
        "--log-level": ["--log-level", "loud"],
        "--ros2": ["--ros2=maybe"],
        "--ros2-namespace": ["--ros2", "--ros2-namespace", "no space"],
        "--groups": ["--groups", "9"],
        "--json": ["--json=maybe"],
        "--count": ["--count", "-1"],
        "--timeout": ["--timeout", "-1"],
    },
    "rsg_record": {
        **DDS_READER,
        "--out": ["--out", NO_DIR + "/out.mcap"],
        "--status-topic": ["--status-topic", CONTROL],
        "--profile": ["--profile", "mp4"],
        "--duration": ["--duration", "-1"],
        "--recover": ["--recover", MISSING],
        "--split-size": ["--split-size", "-1"],
        "--max-files": ["--split-size", "1", "--max-files", "1"],
        "--max-size": ["--split-size", "1", "--max-size", "0"],
        "--max-age": ["--split-size", "1", "--max-age", "0"],
        "--trigger": ["--trigger", "always"],
        "--pre": ["--trigger", "signal", "--pre", "-1"],
        "--post": ["--trigger", "signal", "--post", "-1"],
        "--trigger-buffer": ["--trigger", "signal", "--trigger-buffer", "0"],
        "--event-max-duration": ["--trigger", "signal", "--event-max-duration", "0"],
        "--event-max-size": ["--trigger", "signal", "--event-max-size", "-1"],
        "--chunk-size": ["--chunk-size", "10"],
        "--fsync": ["--fsync=maybe"],
    },
    "rsg_replay": {  # BASE has the file only: each case says --to or --domain (they exclude each other)
        **{flag: ["--domain", "0", *DDS_READER[flag]]
           for flag in ("--topic", "--partition", "--profiles", "--participant-profile", "--discovery-server",
                        "--peer")},
        "--domain": DDS_READER["--domain"],
        "--to": ["--to", BAD_HOST_PORT],
        "--writer-profile": ["--domain", "0", "--writer-profile", "writer_nonexistent"],
        "--wait-for-readers": ["--domain", "0", "--wait-for-readers", "-1"],
        "--speed": ["--to", "127.0.0.1:9", "--speed", "0"],
        "--loop": ["--to", "127.0.0.1:9", "--loop=maybe"],
    },
    "rsg_sim": {
        "--to": ["--to", BAD_HOST_PORT],
        "--rate": ["--rate", "0"],
        "--count": ["--count", "-1"],
        "--duration": ["--duration", "0"],
        "--seed": ["--seed", "-1"],
        "--groups": ["--groups", "9"],
        "--fields": ["--fields", "qq"],
        "--every": ["--every", "x"],
        "--report": ["--report", NO_DIR + "/report.json"],
        "--record": ["--record", NO_DIR + "/record.jsonl"],
        "--pcap": ["--pcap", NO_DIR + "/out.pcap"],
        "--drop": ["--drop", "2"],
        "--duplicate": ["--duplicate", "2"],
        "--reorder": ["--reorder", "2"],
        "--corrupt": ["--corrupt", "2"],
        "--drop-every": ["--drop-every", "-1"],
        "--duplicate-every": ["--duplicate-every", "-1"],
        "--reorder-every": ["--reorder-every", "-1"],
        "--corrupt-every": ["--corrupt-every", "-1"],
        "--corrupt-categories": ["--corrupt-categories", "bad_luck"],
        "--pause-after": ["--pause-after", "-1"],
        "--pause-ms": ["--pause-after", "1", "--pause-ms", "-1"],
        "--restart-after": ["--restart-after", "-1"],
        "--replay": ["--replay", MISSING],
        "--speed": ["--replay", "{pcap}", "--speed", "0"],
        "--loop": ["--replay", "{pcap}", "--loop=maybe"],
        "--port": ["--replay", "{pcap}", "--port", "70000"],
    },
    "rsg_view": {
        **DDS_READER,
        "--log-level": ["--log-level", "loud"],
        "--listen": ["--listen", BAD_HOST_PORT],
        "--status-topic": ["--status-topic", CONTROL],
        "--max-clients": ["--max-clients", "0"],
        "--max-clients-per-address": ["--max-clients-per-address", "0"],
        "--queue-depth": ["--queue-depth", "0"],
        "--page-rate": ["--page-rate", "0"],
        "--chart-js": ["--chart-js", MISSING],
        "--max-connections": ["--max-connections", "0"],
        "--max-connections-per-address": ["--max-connections-per-address", "0"],
        "--max-subscriptions": ["--max-subscriptions", "0"],
        "--max-client-buffer": ["--max-client-buffer", "10"],
        "--handshake-timeout": ["--handshake-timeout", "0"],
        "--idle-timeout": ["--idle-timeout", "0"],
        "--stall-timeout": ["--stall-timeout", "0"],
    },
    "rsg_frame decode": {"--hex-lines": ["--hex-lines=maybe"]},
    "rsg_frame encode": {"--hex-lines": ["--hex-lines=maybe"]},
    "rsg_frame request": {
        "--packet-number": ["--packet-number", "16"],
        "--hex": ["--hex=maybe"],
        "--groups": ["--groups", "9"],
        "--fields": ["--fields", "qq"],
    },
    "rsg_wireshark_lua": {},
}
# The base arguments of a program whose case names the flag too are replaced, not added to.
BASE_REPLACED = {("rsg_record", "--out"), ("rsg_gateway", "--listen"), ("rsg_view", "--listen"),
                 ("rsg_sim", "--to")}

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
        print(f"FAIL: {message}", file=sys.stderr)


def run(command, timeout=20):
    try:
        done = subprocess.run(command, capture_output=True, timeout=timeout, check=False, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        return None, "", f"(still running after {timeout} s: the bad value was accepted)"
    return done.returncode, done.stdout.decode(errors="replace"), done.stderr.decode(errors="replace")


def help_flags(command):
    """The flags (each a tuple of its names) and the subcommands that `command --help` lists."""
    status, out, _ = run([*command, "--help"])
    if status != 0:
        return [], []
    flags, subcommands, section = [], [], None
    for line in out.splitlines():
        if line.startswith("Options:") or line.startswith("[Option Group"):
            section = "options"
        elif line.startswith("Subcommands:"):
            section = "subcommands"
        elif line.startswith("Positionals:"):
            section = "positionals"
        elif line and not line[0].isspace():
            section = None  # the footer
        elif section == "options":
            match = re.match(r"\s+((?:-\w,)?--[\w-]+(?:,--[\w-]+)*)(?:\s|$)", line)
            if match:
                flags.append(tuple(name for name in match.group(1).split(",") if name.startswith("--")))
        elif section == "subcommands":
            match = re.match(r"\s+([a-z][\w-]*)\s", line)
            if match:
                subcommands.append(match.group(1))
    return flags, subcommands


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(f"usage: {sys.argv[0]} BIN_DIR [TEST_BIN_DIR]")
    bin_dir = sys.argv[1]
    test_bin_dir = sys.argv[2] if len(sys.argv) == 3 else os.path.join(bin_dir, "..", "tests", "bin")
    cases = 0
    with tempfile.TemporaryDirectory() as tmp:
        open(os.path.join(tmp, "empty"), "wb").close()
        files = {"tmp": tmp, "pcap": os.path.join(tmp, "in.pcap"), "mcap": os.path.join(tmp, "in.mcap")}
        # A capture for rsg_sim --replay and a recording for rsg_replay: a few frames to the discard
        # port on loopback, and a recording on a domain nobody else uses.
        run([os.path.join(bin_dir, "rsg_sim"), "--to", "127.0.0.1:9", "--count", "3", "--pcap", files["pcap"]])
        run([os.path.join(bin_dir, "rsg_record"), "--out", files["mcap"], "--duration", "0.1", "--domain",
             str(100 + os.getpid() % 100)])
        for name in ("pcap", "mcap"):
            check(os.path.exists(files[name]), f"could not make the {name} file the cases need")

        programs = {}
        for tool in ("rsg_gateway", "rsg_echo", "rsg_record", "rsg_replay", "rsg_sim", "rsg_view", "rsg_frame",
                     "rsg_wireshark_lua"):
            binary = os.path.join(test_bin_dir if tool == "rsg_wireshark_lua" else bin_dir, tool)
            if not os.access(binary, os.X_OK):
                check(False, f"{binary} is not built")
                continue
            flags, subcommands = help_flags([binary])
            check(flags, f"{tool} --help lists no options")
            if subcommands:
                for sub in subcommands:
                    programs[f"{tool} {sub}"] = ([binary, sub], help_flags([binary, sub])[0])
            else:
                programs[tool] = ([binary], flags)
        check(set(programs) == set(BAD_VALUES),
              f"the programs are {sorted(programs)}, BAD_VALUES covers {sorted(BAD_VALUES)}")

        for program, (command, flags) in programs.items():
            table = BAD_VALUES.get(program, {})
            listed = set()
            for names in flags:
                listed.update(names)
                if set(names) & NO_VALUE:
                    continue
                key = next((name for name in names if name in table), None)
                if key is None:
                    check(False, f"{program} {'/'.join(names)}: no bad value in BAD_VALUES (add one)")
                    continue
                base = [] if (program, key) in BASE_REPLACED else BASE[program]
                args = [arg.format(**files) for arg in base + table[key]]
                status, out, err = run(command + args)
                cases += 1
                shown = " ".join(repr(arg) if not arg or "\n" in arg or " " in arg else arg for arg in args)
                tool = os.path.basename(command[0])
                check(status == 2, f"{program} {shown}: exit {status}, expected 2 ({err.strip()!r})")
                check(err.startswith(f"{tool}: "), f"{program} {shown}: stderr does not start '{tool}: ': {err!r}")
                check(any(name in err for name in names),
                      f"{program} {shown}: stderr does not name {'/'.join(names)}: {err.strip()!r}")
                check(out == "", f"{program} {shown}: wrote to stdout: {out!r}")
            stale = set(table) - listed
            check(not stale, f"{program}: BAD_VALUES names flags its --help does not list: {sorted(stale)}")
    if failures:
        sys.exit(f"{len(failures)} failed")
    print(f"{cases} flags of {len(programs)} programs: each bad value exits 2 with a message naming the flag")


if __name__ == "__main__":
    main()
