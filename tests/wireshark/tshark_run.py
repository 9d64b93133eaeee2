"""Runs Debian's tshark with rsg's dissector and returns its -T fields output as dicts."""

import atexit
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

DISSECTOR = Path(__file__).resolve().parents[2] / "tools" / "wireshark" / "rsg_sendbuf.lua"


# A HOME of its own: tshark then loads no personal plugins or preferences, so a dissector installed
# with `make wireshark-plugin` cannot clash with the one under test.
_HOME = tempfile.mkdtemp(prefix="rsg_tshark_home_")
atexit.register(shutil.rmtree, _HOME, ignore_errors=True)
ENV = {**os.environ, "HOME": _HOME, "XDG_CONFIG_HOME": _HOME}


def tshark_path():
    path = shutil.which("tshark")
    if path is None:
        raise SystemExit("FAIL: tshark is not installed (docker/packages.txt lists it; run `make deps`)")
    return path


def ports_decoded_by_number():
    """The UDP ports this tshark hands to a dissector by number (`tshark -G decodes`)."""
    done = subprocess.run([tshark_path(), "-G", "decodes"], capture_output=True, text=True, timeout=60, env=ENV)
    if done.returncode != 0:
        raise AssertionError(f"tshark -G decodes failed ({done.returncode}): {done.stderr}")
    return {int(row.split("\t")[1]) for row in done.stdout.splitlines() if row.startswith("udp.port\t")}


def fields(capture, names, display_filter=None, options=(), dissector=DISSECTOR):
    """One dict per packet: field name -> list of its occurrences (empty when absent)."""
    argv = [tshark_path(), "-n", "-r", str(capture), "-X", f"lua_script:{dissector}", "-T", "fields",
            "-E", "separator=\t", "-E", "occurrence=a", "-E", "aggregator=\x1f"]
    for option in options:
        argv += ["-o", option]
    if display_filter:
        argv += ["-Y", display_filter]
    for name in names:
        argv += ["-e", name]
    done = subprocess.run(argv, capture_output=True, text=True, timeout=120, check=False, env=ENV)
    errors = [line for line in done.stderr.splitlines() if "Running as user" not in line and line.strip()]
    if done.returncode != 0 or errors:
        raise AssertionError(f"tshark failed ({done.returncode}): {done.stderr}")
    rows = []
    for line in done.stdout.split("\n"):
        if not line:
            continue
        values = line.split("\t")
        rows.append({name: (value.split("\x1f") if value else []) for name, value in zip(names, values)})
    return rows
