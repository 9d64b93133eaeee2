"""Every rsg DDS program takes --discovery-server and --peer, with the same checks: a value that is
not [ID@]HOST:PORT / HOST[:PORT] is a usage error (exit 2) naming the value. (That the options work
is net.discovery's job, across namespaces.)"""

import argparse
import subprocess
import sys
from pathlib import Path

PROGRAMS = ["rsg_gateway", "rsg_echo", "rsg_record", "rsg_replay", "rsg_view"]
BAD = [("--discovery-server", "198.18.0.2", "HOST:PORT"), ("--discovery-server", "300@198.18.0.2:11811", "0..255"),
       ("--peer", "198.18.0.2:0", "port")]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", required=True)
    directory = Path(parser.parse_args().bin)
    failures = []
    for program in PROGRAMS:
        path = directory / program
        if not path.exists():
            failures.append(f"{path} is not built")
            continue
        help_text = subprocess.run([path, "--help"], capture_output=True, text=True).stdout
        for flag in ("--discovery-server", "--peer"):
            if flag not in help_text:
                failures.append(f"{program} --help lists no {flag}")
        for flag, value, expected in BAD:
            result = subprocess.run([path, flag, value], capture_output=True, text=True, timeout=20)
            output = result.stdout + result.stderr
            if result.returncode != 2 or value not in output or expected not in output:
                failures.append(f"{program} {flag} {value}: exit {result.returncode}, wanted 2 and a message "
                                f"naming the value and '{expected}':\n{output.strip()[:300]}")
    for failure in failures:
        print("FAILED:", failure)
    print("passed" if not failures else f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
