#!/usr/bin/env python3
"""Every rsg executable exits as CONTRIBUTING.md ("Errors") writes it, through the one main()
skeleton (src/app/tool_main.hpp): --help is 0 with the usage on stdout; a flag it does not know
is 2, one line on stderr, "<tool>: <what> (see --help)" (what CLI11 finds first: an unknown flag or
a missing required one); an input file that does not exist is 2 too
(rsg::InputError), and nothing is started.

Run by ctest as tools.exit_statuses (label `cli`); by hand:
    tests/tools/test_exit_statuses.py build/bin src [build/tests/bin]
(the tools are in build/bin; rsg_wireshark_lua, which is not installed, is in build/tests/bin:
CONTRIBUTING.md, "Build tree").
The list below must name every add_executable() under src/: a new executable fails this test until
it is added.
Standard library only.
"""

import os
import re
import subprocess
import sys
import tempfile

MISSING = "/nonexistent/rsg-exit-statuses-input"

# Each executable, with arguments naming an input file that does not exist (an rsg::InputError).
EXECUTABLES = {
    "rsg_gateway": [["--config", MISSING], ["--listen", "127.0.0.1:0", "--profiles", MISSING]],
    "rsg_sim": [["--to", "127.0.0.1:9", "--replay", MISSING]],
    "rsg_echo": [["--profiles", MISSING]],
    "rsg_frame": [["decode", MISSING], ["decode", "--hex-lines", MISSING], ["encode", MISSING]],
    "rsg_record": [["--out", "{tmp}/out.mcap", "--recover", MISSING], ["--out", "{tmp}/out.mcap", "--profiles", MISSING]],
    "rsg_replay": [[MISSING, "--to", "127.0.0.1:9"]],
    "rsg_view": [["--listen", "127.0.0.1:0", "--profiles", MISSING]],
    "rsg_wireshark_lua": [[MISSING, "{tmp}/out.lua"]],
}

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)
        print(f"FAIL: {message}", file=sys.stderr)


def run(binary, args):
    done = subprocess.run([binary, *args], capture_output=True, timeout=60, check=False, stdin=subprocess.DEVNULL)
    return done.returncode, done.stdout.decode(errors="replace"), done.stderr.decode(errors="replace")


def executable(tool, *directories):
    """The path of `tool` in the first of `directories` that has it (else in the first)."""
    paths = [os.path.join(directory, tool) for directory in directories]
    return next((path for path in paths if os.access(path, os.X_OK)), paths[0])


def built_executables(source_dir):
    """The names of every add_executable() in the CMakeLists.txt files under `source_dir`."""
    names = set()
    for folder, _, files in os.walk(source_dir):
        if "CMakeLists.txt" in files:
            with open(os.path.join(folder, "CMakeLists.txt"), encoding="utf-8") as cmake:
                names.update(re.findall(r"add_executable\(\s*([A-Za-z0-9_]+)", cmake.read()))
    return names


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(f"usage: {sys.argv[0]} BIN_DIR SOURCE_DIR [TEST_BIN_DIR]")
    bin_dir, source_dir = sys.argv[1:3]
    test_bin_dir = sys.argv[3] if len(sys.argv) == 4 else os.path.join(bin_dir, "..", "tests", "bin")
    built = built_executables(source_dir)
    check(built == set(EXECUTABLES),
          f"the executables under {source_dir} are {sorted(built)}, this test covers {sorted(EXECUTABLES)}")
    with tempfile.TemporaryDirectory() as tmp:
        for tool, missing_inputs in EXECUTABLES.items():
            binary = executable(tool, bin_dir, test_bin_dir)
            if not os.access(binary, os.X_OK):
                check(False, f"{binary} is not built (cmake --build build --target {tool})")
                continue
            status, out, err = run(binary, ["--help"])
            check(status == 0 and "Usage" in out, f"{tool} --help: exit {status}, stdout {out[:80]!r}")

            status, out, err = run(binary, ["--no-such-flag"])
            check(status == 2, f"{tool} --no-such-flag: exit {status}, expected 2 ({err.strip()})")
            check(err.startswith(f"{tool}: ") and err.endswith(" (see --help)\n") and err.count("\n") == 1,
                  f"{tool} --no-such-flag: stderr is not one line '{tool}: ... (see --help)': {err!r}")
            check(out == "", f"{tool} --no-such-flag wrote to stdout: {out!r}")

            for args in missing_inputs:
                args = [arg.format(tmp=tmp) for arg in args]
                status, out, err = run(binary, args)
                check(status == 2, f"{tool} {' '.join(args)}: exit {status}, expected 2 ({err.strip()})")
                check(err.startswith(f"{tool}: ") and MISSING in err,
                      f"{tool} {' '.join(args)}: stderr does not read '{tool}: ...{MISSING}...': {err.strip()!r}")
    if failures:
        sys.exit(f"{len(failures)} failed")
    print(f"{len(EXECUTABLES)} executables: --help 0, a bad flag 2, a missing input file 2")


if __name__ == "__main__":
    main()
