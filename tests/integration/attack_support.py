"""What the attack tests (test_attack_*.py) share: the gateway with a legitimate reader, a flood of
junk from another loopback address, the bytes of a folder, the senders recorded in a flight-recorder dump, and a scrape checked by
promtool."""

import os
import socket
import struct
import subprocess
import threading
import time
import zlib

from harness import check, wait_for, wait_for_stats, wait_reader_matched
from metrics_support import http_get, parse_samples, require_tool

LINKTYPE_RAW = 101  # what the gateway's dumps hold (src/capture/pcap_file.hpp)


def valid_frame(number, time_ms, q=0.0):
    """A valid frame carrying q and time (CRC right), packet number `number` (mod 16): what a robot,
    or anyone who forges one, sends. q is field 21 (group 2, bit 5), time field 43 (group 5, bit 3):
    docs/protocol.md."""
    data = struct.pack("<7d", *([q] * 7)) + struct.pack("<Q", time_ms)
    selection = bytes([0b100100, 0, 0, 0x20, 0, 0, 0x08])  # group_select, then data_select[0..5]
    body = bytes([0x30 | (number % 16)]) + struct.pack("<H", len(data)) + selection + data
    return body + struct.pack("<I", zlib.crc32(body))


def send_frames(port, count, rate, source="127.0.0.1", first=0):
    """`count` frames in step (numbers and times from `first`), `rate` a second, from `source` to the
    gateway on 127.0.0.1:`port`."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        sender.bind((source, 0))
        start = time.monotonic()
        for i in range(count):
            delay = start + i / rate - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            sender.sendto(valid_frame(first + i, int((first + i) * 1000 / rate)), ("127.0.0.1", port))


class JunkFlood(threading.Thread):
    """Random datagrams from `source` (another loopback address: not --allow-from's 127.0.0.1) to
    `port`, `rate` a second, until stopped. `sent` counts them."""

    def __init__(self, port, source="127.0.0.2", rate=3000, size=1400):
        super().__init__(daemon=True)
        self.port, self.source, self.rate, self.size = port, source, rate, size
        self.sent = 0
        self._stopping = threading.Event()

    def run(self):
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
            sender.bind((self.source, 0))
            start = time.monotonic()
            while not self._stopping.is_set():
                due = int((time.monotonic() - start) * self.rate)
                while self.sent < due:
                    sender.sendto(os.urandom(self.size), ("127.0.0.1", self.port))
                    self.sent += 1
                time.sleep(0.002)

    def stop(self):
        self._stopping.set()
        self.join(timeout=5)


def folder_bytes(folder):
    """The bytes of the regular files directly in `folder`."""
    return sum(path.stat().st_size for path in folder.iterdir() if path.is_file())


def dump_senders(path):
    """The source address of every datagram of a flight-recorder dump (a LINKTYPE_RAW pcap file)."""
    data = path.read_bytes()
    check(len(data) >= 24 and struct.unpack_from("<I", data, 0)[0] == 0xA1B2C3D4, f"{path.name} is not a pcap file")
    check(struct.unpack_from("<I", data, 20)[0] == LINKTYPE_RAW, f"{path.name} is not LINKTYPE_RAW")
    senders, offset = [], 24
    while offset + 16 <= len(data):
        captured = struct.unpack_from("<IIII", data, offset)[2]
        packet = data[offset + 16:offset + 16 + captured]
        offset += 16 + captured
        senders.append(socket.inet_ntoa(packet[12:16]) if packet[0] >> 4 == 4 else "IPv6")
    return senders


def checked_scrape(h, metrics_port, label):
    """The samples of one /metrics scrape, after `promtool check metrics` accepted it."""
    promtool = require_tool("promtool")
    reply = http_get(metrics_port, "/metrics")
    check(reply is not None and reply[0] == 200, f"/metrics answered {reply and reply[0]}")
    (h.dir / f"{label}.metrics.txt").write_text(reply[1])
    lint = subprocess.run([promtool, "check", "metrics"], input=reply[1], capture_output=True, text=True, timeout=30)
    check(lint.returncode == 0 and not lint.stdout.strip() and not lint.stderr.strip(),
          f"promtool check metrics (exit {lint.returncode}): {lint.stdout}{lint.stderr}")
    return parse_samples(reply[1])


def gateway_with_reader(h, metrics_port, frames, *flags):
    """The gateway (`flags`, /metrics on `metrics_port`) and a legitimate reader, rsg_echo, that exits
    0 once it has printed `frames` samples; returns (gateway, stats file, echo) once both sides of
    discovery matched."""
    gateway, stats = h.gateway("gateway", *flags)
    wait_for(lambda: gateway.poll() is not None or http_get(metrics_port, "/metrics"), "the gateway's /metrics")
    check(gateway.poll() is None, f"the gateway exited {gateway.poll()} at start")
    echo = h.start("echo", [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "robot_state", "--json",
                            "--count", str(frames), "--timeout", "45"])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, "rsg_echo's reader to match the gateway's writer")
    wait_reader_matched(h, "echo", "rsg_echo")
    return gateway, stats, echo
