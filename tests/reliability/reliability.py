"""What the reliability tests share: starting the gateway, readers and the simulator, checking the
gateway's counters against the simulator's report, delivery against the simulator's record,
process memory, and timing bounds.

Process plumbing (scratch directory, DDS domain, ports, killing children, bounded waits) is the
integration tests' harness, imported unchanged from tests/integration.
"""

import os
import signal
import sys
import time
from pathlib import Path

from harness import (TestFailure, check, free_udp_port, main, read_json, read_json_lines,  # noqa: E402,F401
                     wait_for, wait_for_stats)

# A requirement's time bound (100 ms link-down detection, 2 s resume) is asserted with this much
# headroom: on a 2-core CI machine shared with builds, a scheduling hiccup of tens of ms is normal
# and is not what these tests look for. The measured value is printed either way, and a value
# above the requirement itself (but within the margin) is printed as a warning.
LOADED_CI_MARGIN = 1.5

# The gateway's counters that the simulator's report determines.
SEQUENCE_COUNTERS = ("lost", "duplicated", "reordered", "robot_restarts")


def log(h, message):
    print(f"[{h.name}] {message}", flush=True)


def measured(h, what, value_s, requirement_s):
    """Prints a measured duration and asserts it within the requirement times LOADED_CI_MARGIN."""
    verdict = "within" if value_s <= requirement_s else "WARNING: over"
    log(h, f"MEASURED {what}: {value_s * 1000:.1f} ms ({verdict} the {requirement_s * 1000:.0f} ms requirement)")
    check(value_s <= requirement_s * LOADED_CI_MARGIN,
          f"{what} took {value_s * 1000:.1f} ms, above {requirement_s * 1000:.0f} ms x {LOADED_CI_MARGIN}")


# ----- gateway -------------------------------------------------------------------------------------

def start_gateway(h, rate_hz, port=None, label="gateway", extra=()):
    """Starts rsg_gateway on 127.0.0.1:`port` (a free one by default) and waits for its first stats
    file. Returns (process, stats path, port)."""
    port = port or free_udp_port()
    process, stats = h.gateway(label, "--listen", f"127.0.0.1:{port}", "--expected-rate", str(rate_hz), *extra)
    wait_for_stats(stats, lambda s: True, f"{label} to start")
    return process, stats, port


def wait_for_readers(stats, count):
    """Waits until the gateway's RobotState writer has matched `count` readers."""
    return wait_for_stats(stats, lambda s: s["state_readers"] >= count, f"{count} reader(s) to match the gateway")


def settled_stats(stats, report):
    """The gateway's stats once it has counted every datagram the simulator sent."""
    return wait_for_stats(stats, lambda s: s["frames_received"] >= report["sent"],
                          f"the gateway to count all {report['sent']} datagrams sent")


def expected_counters(report, out_of_sequence=0):
    """What the gateway must count for a simulator run, from the simulator's report: every datagram,
    every valid frame published but the `out_of_sequence` ones (docs/operating.md: a frame whose time
    goes back is counted, not published), invalid ones by category, and the sequence faults (a
    corrupted frame replaces a valid one and leaves a packet-number gap, but it arrived: invalid, not
    lost). No run here turns the standard ROS 2 topics on, so none of their snapshots can be dropped."""
    return {"frames_received": report["sent"], "frames_published": report["valid"] - out_of_sequence,
            "publish_failed": 0, "invalid": report["invalid"], "lost": report["dropped"],
            "duplicated": report["duplicated"], "reordered": report["reordered"],
            "robot_restarts": report["restarts"], "standard_dropped": 0}


def check_counters(actual, report, where="stats file", out_of_sequence=0):
    """The gateway's counters (stats file or status sample) equal what the simulator injected;
    `out_of_sequence` valid frames were not published (the status topic does not carry that count)."""
    expected = expected_counters(report, out_of_sequence)
    if "out_of_sequence" in actual:
        expected["out_of_sequence"] = out_of_sequence
    got = {key: actual[key] for key in expected}
    check(got == expected, f"gateway {where} {got}\n  != simulator report {expected}")


def vm_kib(pid, field):
    """A /proc/PID/status memory line (VmRSS: resident now, VmHWM: peak resident), in KiB."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1])
    raise TestFailure(f"no {field} in /proc/{pid}/status")


def udp_socket_drops(port):
    """Datagrams the kernel dropped for the UDP socket bound to `port` (its receive buffer was full),
    from the `drops` column of /proc/net/udp; None when no socket is bound there."""
    for line in Path("/proc/net/udp").read_text().splitlines()[1:]:
        fields = line.split()
        if int(fields[1].split(":")[1], 16) == port:
            return int(fields[-1])
    return None


# ----- simulator and readers -----------------------------------------------------------------------

def run_sim(h, port, rate_hz, count, *flags, label="sim", timeout_s=60.0):
    """Runs rsg_sim to completion; returns (report, record path, wall-clock seconds it streamed)."""
    record, report = h.dir / f"{label}.record.jsonl", h.dir / f"{label}.report.json"
    started = time.monotonic()
    status = h.run(label, [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", str(rate_hz),
                           "--count", str(count), *flags, "--record", str(record), "--report", str(report)],
                   timeout_s=timeout_s)
    elapsed = time.monotonic() - started
    check(status == 0, f"rsg_sim exited {status}")
    return read_json(report), record, elapsed


def start_logger(h, label, timeout_s=45):
    """A reliable logger: rsg_echo --json with the reader_logger profile, one JSON line per sample."""
    return h.start(label, [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "robot_state", "--json",
                           "--qos", "reader_logger", "--timeout", str(timeout_s)])


def logged_samples(h, label):
    return read_json_lines(h.output(label))


def check_delivered_exactly_once(h, label, record, timeout_s=30.0):
    """Every valid frame the simulator sent reached reader `label` exactly once, in order, with the
    values sent: its JSON lines equal the simulator's record, line for line (so a sample lost,
    duplicated, reordered or altered fails; at > 1 kHz `time` repeats, but the packet number and
    the values still pin each frame to its place in the sequence). Delivery is in order, so once the
    last frame sent has arrived nothing earlier is still on its way."""
    sent = read_json_lines(record)
    wait_for(lambda: logged_samples(h, label)[-1:] == sent[-1:], f"{label} to print the last frame sent", timeout_s)
    received = logged_samples(h, label)
    check(len(received) == len(sent), f"{label} printed {len(received)} samples for {len(sent)} valid frames"
                                      f"{missing_runs(sent, received)}")
    for index, (expected, actual) in enumerate(zip(sent, received)):
        check(actual == expected, f"{label}: sample {index} differs from the frame sent:\n"
                                  f"  sent {expected}\n  got  {actual}")
    return len(received)


def missing_runs(sent, received):
    """'; missing frames a..b, c..d' when `received` is `sent` with some frames left out, else ''."""
    missing, at = [], 0
    for index, frame in enumerate(sent):
        if at < len(received) and received[at] == frame:
            at += 1
        elif not missing or missing[-1][1] != index - 1:
            missing.append([index, index])
        else:
            missing[-1][1] = index
    if at != len(received) or not missing:
        return ""
    return "; missing frames " + ", ".join(f"{a}..{b}" for a, b in missing)


def stop_child(h, label, process):
    """SIGTERM and a bounded wait: ends a reader that runs without --count."""
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)
    return h.wait(label, process)


class DeadlineProbe:
    """rsg_deadline_probe: RobotState arrivals (reader_realtime), deadline misses and status samples
    as JSON lines with CLOCK_MONOTONIC timestamps (`t`, comparable with time.monotonic())."""

    def __init__(self, h, label="deadline_probe", timeout_s=55, qos=None):
        self.h, self.label = h, label
        self.process = h.start(label, [h.binary("rsg_deadline_probe"), "--domain", str(h.domain),
                                       "--timeout", str(timeout_s), *(["--qos", qos] if qos else [])])

    def events(self, kind=None):
        lines = read_json_lines(self.h.output(self.label))
        return [line for line in lines if kind is None or line["event"] == kind]

    def wait_for_status(self):
        """The status writer is transient-local: a matched probe gets the current status at once."""
        return wait_for(lambda: self.events("status"), f"{self.label} to receive a gateway status")

    def link_changes(self):
        """The status samples where link_up differs from the previous one (the first one included)."""
        changes, previous = [], None
        for status in self.events("status"):
            if status["link_up"] != previous:
                changes.append(status)
                previous = status["link_up"]
        return changes


# ----- load --------------------------------------------------------------------------------------

class BusyLoop:
    """Another process spinning on a CPU for the duration of a `with` block: on a 2-core machine, it
    takes a whole core away from the gateway, the simulator and the readers."""

    def __init__(self, h, cpu=None):
        self.h, self.cpu = h, cpu

    def __enter__(self):
        self.process = self.h.start("busy_loop", [sys.executable, "-c", "while True: pass"])
        if self.cpu is not None:
            os.sched_setaffinity(self.process.pid, {self.cpu})
        return self

    def __exit__(self, *exc):
        self.process.kill()
        self.process.wait()


def fastdds_shm_segments():
    """Fast DDS shared-memory files in /dev/shm (segments and port queues)."""
    return sorted(p.name for p in Path("/dev/shm").glob("fastrtps_*"))


def monotonic():
    return time.monotonic()
