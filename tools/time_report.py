#!/usr/bin/env python3
"""make time-report: where the time of a fresh build and of the tests goes (issue 27, "measure first").

    tools/time_report.py [--build DIR] [--skip-build] [--skip-tests] [--top N]

1. Configures DIR (default build-time) with Ninja and the flags of `make build`, with the compiler
   cache off (CCACHE_DISABLE=1: the figures are what a fresh clone pays), builds everything and
   prints the N slowest translation units and targets from Ninja's own log (.ninja_log: start and
   end of every step, in ms), with the build's wall time and summed compile time.
2. Runs ctest there serially (-j1: each test's time is its own; make test runs them side by side, with
   the long ones in make test-long) and prints the N slowest tests and the total.
Both tables are Markdown, to paste into docs/development.md with the CPU that measured them
(printed first).
"""
import argparse
import os
import re
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def cpu_model():
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "?"


def ninja_steps(build):
    """(seconds, output) per step of the last build, from .ninja_log (v5: start end mtime output hash)."""
    steps = {}
    for line in (build / ".ninja_log").read_text().splitlines():
        if line.startswith("#"):
            continue
        start, end, _, output, *_ = line.split("\t")
        steps[output] = (int(end) - int(start)) / 1000.0
    return sorted(((s, o) for o, s in steps.items()), reverse=True)


def ctest_times(log):
    """(seconds, name) per test from ctest's progress lines."""
    pattern = re.compile(r"Test +#\d+: (\S+) \.+.*?([\d.]+) sec")
    return sorted(((float(m.group(2)), m.group(1)) for m in map(pattern.search, log.splitlines()) if m), reverse=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--build", default=str(REPO / "build-time"))
    parser.add_argument("--skip-build", action="store_true", help="report the last build in DIR")
    parser.add_argument("--skip-tests", action="store_true")
    parser.add_argument("--top", type=int, default=20)
    args = parser.parse_args()
    build = Path(args.build)
    print(f"CPU: {cpu_model()}, {os.cpu_count()} cores")
    if not args.skip_build:
        env = {**os.environ, "CCACHE_DISABLE": "1"}
        subprocess.run(["cmake", "-S", str(REPO), "-B", str(build), "-G", "Ninja", "-DCMAKE_BUILD_TYPE=RelWithDebInfo",
                        # make build's OPT_FLAGS (Makefile): -O2 with line tables only
                        "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG", "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG",
                        "-DRSG_BUILD_TESTS=ON", f"-DRSG_DEPS_DIR={REPO / '.deps'}"], check=True, env=env, stdout=subprocess.DEVNULL)
        subprocess.run(["ninja", "-C", str(build), "-t", "clean"], check=True, stdout=subprocess.DEVNULL)
        started = time.monotonic()
        subprocess.run(["ninja", "-C", str(build), f"-j{os.cpu_count()}"], check=True, env=env,
                       stdout=subprocess.DEVNULL)
        print(f"\nbuild wall time: {time.monotonic() - started:.0f} s")
    steps = ninja_steps(build)
    compiles = [(s, o) for s, o in steps if o.endswith(".o")]
    print(f"translation units: {len(compiles)}, compile time summed: {sum(s for s, _ in compiles):.0f} s; "
          f"all steps summed: {sum(s for s, _ in steps):.0f} s\n")
    print("| s | slowest steps (translation units, links, generators) |\n|---:|---|")
    for seconds, output in steps[:args.top]:
        print(f"| {seconds:.1f} | `{output}` |")
    if args.skip_tests:
        return 0
    started = time.monotonic()
    run = subprocess.run(["ctest", "-j1"], cwd=build, capture_output=True, text=True)
    (build / "ctest-time-report.log").write_text(run.stdout + run.stderr)
    tests = ctest_times(run.stdout)
    print(f"\nctest wall time: {time.monotonic() - started:.0f} s, {len(tests)} tests, "
          f"summed {sum(s for s, _ in tests):.0f} s (exit {run.returncode})\n")
    print("| s | slowest tests |\n|---:|---|")
    for seconds, name in tests[:args.top]:
        print(f"| {seconds:.1f} | `{name}` |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
