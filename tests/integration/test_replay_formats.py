"""rsg_sim --replay reads what capture tools write: pcapng (converted by Debian's editcap), Ethernet
with a VLAN tag, Linux cooked captures, and full frames split into IPv4 fragments as a 1500-byte
MTU does (out of order, interleaved with other traffic). Every SEND_BUF datagram to the chosen port
arrives byte for byte, in order, and nothing else does; with --loop, over and over."""

import json
import signal
import socket
import struct
import subprocess
import sys
from pathlib import Path

from harness import check, main

VECTORS = Path(__file__).resolve().parents[1] / "data" / "vectors"
PORT = 17000


def ipv4(payload, ident, flags_offset=0x4000):
    header = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(payload), ident, flags_offset, 64, 17, 0,
                         bytes([10, 0, 0, 2]), bytes([10, 0, 0, 1]))
    total = sum(struct.unpack("!10H", header))
    while total > 0xFFFF:
        total = (total & 0xFFFF) + (total >> 16)
    return header[:10] + struct.pack("!H", ~total & 0xFFFF) + header[12:] + payload


def udp(payload, destination_port):
    return struct.pack("!HHHH", 40000, destination_port, 8 + len(payload), 0) + payload


def fragments(datagram, ident):
    """IPv4 fragments of at most 1480 payload bytes (a 1500-byte MTU), last one first."""
    pieces = [datagram[i:i + 1480] for i in range(0, len(datagram), 1480)]
    out = []
    for index, piece in enumerate(pieces):
        more = 0x2000 if index < len(pieces) - 1 else 0
        out.append(ipv4(piece, ident, more | (index * 1480 // 8)))
    return out[::-1]


def write_pcap(path, linktype, frames):
    with open(path, "wb") as out:
        out.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, linktype))
        for number, frame in enumerate(frames):
            out.write(struct.pack("<IIII", 1000, number * 500, len(frame), len(frame)) + frame)


def body(h):
    vectors = [bytes.fromhex(json.loads(line)["frame_hex"]) for line in (VECTORS / "valid.jsonl").read_text().splitlines()]
    frames = sorted(vectors, key=len)[-10:] + vectors[:10]  # the largest ones need fragmenting
    packets = []  # IPv4 packets: every frame (fragmented when large) plus a decoy to another port
    for ident, frame in enumerate(frames, start=1):
        datagram = udp(frame, PORT)
        packets += fragments(datagram, ident) if len(datagram) > 1480 else [ipv4(datagram, ident)]
        packets.append(ipv4(udp(b"not for the gateway", 5353), 1000 + ident))
    vlan_ethernet = [bytes(12) + b"\x81\x00\x00\x05\x08\x00" + p for p in packets]
    cooked = [bytes(14) + b"\x08\x00" + p for p in packets]

    receiver = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    receiver.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 << 20)
    receiver.bind(("127.0.0.1", 0))
    receiver.settimeout(10)
    target = f"127.0.0.1:{receiver.getsockname()[1]}"

    captures = {"ethernet_vlan.pcap": (1, vlan_ethernet), "cooked.pcap": (113, cooked)}
    for name, (linktype, link_frames) in captures.items():
        write_pcap(h.dir / name, linktype, link_frames)
    pcapng = h.dir / "ethernet_vlan.pcapng"
    converted = subprocess.run(["editcap", "-F", "pcapng", str(h.dir / "ethernet_vlan.pcap"), str(pcapng)],
                               capture_output=True, text=True)
    check(converted.returncode == 0, f"editcap failed: {converted.stderr}")
    check(pcapng.read_bytes()[:4] == b"\x0a\x0d\x0d\x0a", "editcap did not write pcapng")

    for capture in [h.dir / name for name in captures] + [pcapng]:
        status = h.run(f"replay_{capture.name}", [h.binary("rsg_sim"), "--to", target, "--replay", str(capture),
                                                  "--speed", "10"])
        check(status == 0, f"rsg_sim --replay {capture.name} exited {status}")
        received = []
        receiver.settimeout(2)
        try:
            while True:
                received.append(receiver.recv(65536))
        except socket.timeout:
            pass
        check(received == frames, f"{capture.name}: received {len(received)} datagrams, "
              f"{sum(a == b for a, b in zip(received, frames))} of {len(frames)} as captured")

    # --loop starts over at the end until stopped; SIGINT ends it cleanly.
    looping = h.start("replay_loop", [h.binary("rsg_sim"), "--to", target, "--replay", str(h.dir / "cooked.pcap"),
                                      "--speed", "20", "--loop"])
    received = []
    receiver.settimeout(10)
    while len(received) < 2 * len(frames) + 5:
        received.append(receiver.recv(65536))
    looping.send_signal(signal.SIGINT)
    check(h.wait("replay_loop", looping, 10) == 0, "rsg_sim --loop did not exit 0 on SIGINT")
    check(received == (frames * 3)[:len(received)], "the looped replay is not the capture over and over")


if __name__ == "__main__":
    sys.exit(main("replay_formats", body))
