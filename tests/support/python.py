#!/usr/bin/env python3
"""python3 with tests/support on PYTHONPATH: the one way rsg's Python tests find their shared helpers
(harness.py, test_domain.py, dds_attacks.py), which they import by name, with no sys.path insert of
their own (CONTRIBUTING.md, "Tests").

    tests/support/python.py SCRIPT [ARG...]

puts this folder first on PYTHONPATH, keeping what the caller had there (a ROS 2 environment's), and
execs this interpreter on SCRIPT: the script's own folder is still sys.path[0], and the processes it
starts inherit the path. ctest runs every Python test through it (RSG_PYTHON in the top
CMakeLists.txt); the suites run outside ctest export the same PYTHONPATH (tests/fastdds3/run.sh,
tests/fastdds214/run.sh, tests/bench/run_bench.sh). By hand:

    tests/support/python.py tests/integration/test_sim_to_echo.py --bin build/bin
"""
import os
import sys
from pathlib import Path

SUPPORT = str(Path(__file__).resolve().parent)


def main():
    kept = [path for path in os.environ.get("PYTHONPATH", "").split(os.pathsep) if path and path != SUPPORT]
    os.environ["PYTHONPATH"] = os.pathsep.join([SUPPORT, *kept])
    os.execv(sys.executable, [sys.executable, *sys.argv[1:]])


if __name__ == "__main__":
    main()
