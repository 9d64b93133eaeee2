"""Fast DDS's own log lines (its XMLPARSER, SECURITY, RTPS errors) carry no terminal colour codes
when stderr is not a terminal -- a journal, a file, a pipe -- and keep them on a terminal
(docs/service.md, "The journal"). The line provoked: a profile file Fast DDS rejects (well-formed XML,
a duration that is no number), read by rsg_gateway --check-config.

The control: the same command with stderr on a pseudo-terminal gets the colour codes, so the plain
lines are the consumer's choice, not a Fast DDS without colours."""

import os
import pty
import select
import subprocess
import sys

from harness import check, free_udp_port, main

REJECTED = """<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <profiles>
    <data_writer profile_name="rejected_writer">
      <qos><durability><kind>SOMETIMES</kind></durability></qos>
    </data_writer>
  </profiles>
</dds>
"""
ESC = "\x1b["


def on_terminal(argv):
    """stderr of `argv` run with stderr on a pseudo-terminal (stdout a pipe)."""
    master, slave = pty.openpty()
    process = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=slave)
    os.close(slave)
    out = b""
    while True:
        ready, _, _ = select.select([master], [], [], 30)
        if not ready:
            process.kill()
            break
        try:
            chunk = os.read(master, 65536)
        except OSError:  # EIO: the terminal's other side closed
            break
        if not chunk:
            break
        out += chunk
    os.close(master)
    process.wait(timeout=30)
    return out.decode(errors="replace")


def body(h):
    profile = h.dir / "rejected.xml"
    profile.write_text(REJECTED)
    argv = [h.binary("rsg_gateway"), "--listen", f"127.0.0.1:{free_udp_port()}", "--profiles", str(profile),
            "--check-config"]
    piped = subprocess.run(argv, stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=30)
    check(piped.returncode == 2, f"a rejected profile: exit {piped.returncode}: {piped.stderr!r}")
    check("XMLPARSER" in piped.stderr, f"no Fast DDS XMLPARSER line on stderr: {piped.stderr!r}")
    check(ESC not in piped.stderr, f"colour codes in Fast DDS's lines on a pipe: {piped.stderr!r}")
    line = next(l for l in piped.stderr.splitlines() if "XMLPARSER" in l)
    print(f"[{h.name}] on a pipe: {line!r}")

    terminal = on_terminal(argv)
    check("XMLPARSER" in terminal and ESC in terminal,
          f"the control: on a terminal Fast DDS's lines should be in colour: {terminal!r}")
    print(f"[{h.name}] control, on a terminal: {next(l for l in terminal.splitlines() if 'XMLPARSER' in l)!r}")


if __name__ == "__main__":
    sys.exit(main("fastdds_log", body))
