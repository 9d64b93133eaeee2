"""Under systemd, stderr is a stream to the journal and JOURNAL_STREAM names its device and inode;
rsg_gateway then prefixes each line with its level's syslog priority ("<6>" info, "<4>" warning,
"<3>" error), which journald takes as the entry's priority. Played here with a file: stderr goes to
it and JOURNAL_STREAM names it. A JOURNAL_STREAM naming another file changes nothing. The journal
stamps each entry itself, so the running gateway's lines there carry no time of their own (one
timestamp per line in journalctl), where on a plain stderr they do. --log-format json makes each
line one JSON object: time, level, logger, message; no time in the journal."""

import json
import os
import re
import signal
import subprocess
import sys

from harness import check, free_udp_port, main, wait_for


def stream_of(path):
    status = os.stat(path)
    return f"{status.st_dev}:{status.st_ino}"


def run_gateway(h, label, journal_stream, *flags):
    err = h.dir / f"{label}.err"
    err.touch()
    env = dict(os.environ, JOURNAL_STREAM=journal_stream(err))
    with open(err, "ab") as stderr:
        process = subprocess.Popen([h.binary("rsg_gateway"), "--domain", str(h.domain), *flags],
                                   stdout=subprocess.DEVNULL, stderr=stderr, env=env)
    h.children.append((label, process))
    return process, err


def body(h):
    # A running gateway: info lines, then a warning (SIGUSR1 without a flight recorder).
    gateway, err = run_gateway(h, "gateway", stream_of, "--listen", f"127.0.0.1:{free_udp_port()}")
    wait_for(lambda: "<6>" in err.read_text(), "an info line")
    gateway.send_signal(signal.SIGUSR1)
    wait_for(lambda: "<4>" in err.read_text(), "the SIGUSR1 warning")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    lines = err.read_text().splitlines()
    check(lines and all(line[:3] in ("<6>", "<4>") for line in lines), f"lines without a priority: {lines}")
    check(any(line.startswith("<4>") and "no flight recorder" in line for line in lines), f"no <4> warning: {lines}")
    check(all(line[3:].startswith("rsg_gateway: ") for line in lines),
          f"lines in the journal with a time of their own (the journal has one): {lines}")

    # --log-format json: one object per line, the journal's without a time, a plain stderr's with one.
    gateway, err = run_gateway(h, "json", stream_of, "--listen", f"127.0.0.1:{free_udp_port()}", "--log-format",
                               "json")
    wait_for(lambda: "<6>{" in err.read_text(), "a JSON info line")
    gateway.send_signal(signal.SIGUSR1)
    wait_for(lambda: "<4>{" in err.read_text(), "the SIGUSR1 warning as JSON")
    check(h.stop("json", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    started = err.read_text().splitlines()
    check(all(line[3:].startswith("{") for line in started), f"lines that are not JSON: {started}")
    objects = [json.loads(line[3:]) for line in started]
    check(objects and all(list(o) == ["level", "logger", "message"] for o in objects),
          f"JSON lines in the journal not {{level, logger, message}}: {started}")
    check(any(o["level"] == "warning" and "no flight recorder" in o["message"] for o in objects),
          f"no JSON warning: {started}")
    gateway, err = run_gateway(h, "json_plain", lambda _: "0:0", "--listen", f"127.0.0.1:{free_udp_port()}",
                               "--log-format", "json")
    wait_for(lambda: '"level":"info"' in err.read_text(), "a JSON info line on a plain stderr")
    check(h.stop("json_plain", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    lines = err.read_text().splitlines()
    check(all(line.startswith("{") for line in lines), f"lines that are not JSON: {lines}")
    plain = [json.loads(line) for line in lines]
    check(plain and all(list(o) == ["time", "level", "logger", "message"] and
                        re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z", o["time"]) for o in plain),
          f"JSON lines on a plain stderr not {{time, level, logger, message}}: {err.read_text()}")

    # A refused start: the error that ends it is priority 3.
    refused, err = run_gateway(h, "refused", stream_of, "--listen", "127.0.0.1:99999")
    check(h.wait("refused", refused) == 2, "a bad --listen did not exit 2")
    lines = err.read_text().splitlines()
    check(len(lines) == 1 and lines[0].startswith("<3>rsg_gateway: ") and "--listen" in lines[0],
          f"the refusal: {lines}")

    # JOURNAL_STREAM of another file (stderr is not the journal): lines as ever.
    other = h.dir / "other"
    other.touch()
    refused, err = run_gateway(h, "plain", lambda _: stream_of(other), "--listen", "127.0.0.1:99999")
    check(h.wait("plain", refused) == 2, "a bad --listen did not exit 2")
    lines = err.read_text().splitlines()
    check(len(lines) == 1 and lines[0].startswith("rsg_gateway: "), f"not the journal, yet: {lines}")


if __name__ == "__main__":
    sys.exit(main("journal_priorities", body))
