"""rsg_sim --replay reads what capture tools write: pcapng (converted by Debian's editcap), Ethernet
with a VLAN tag, Linux cooked captures, and full frames split into IPv4 fragments as a 1500-byte
MTU does (out of order, interleaved with other traffic). Every SEND_BUF datagram to the chosen port
arrives byte for byte, in order, and nothing else does; with --loop, over and over. Of a capture
with two SEND_BUF streams on two ports, the first frame's port is replayed by default and --port
picks the other; either keeps the capture's spacing divided by --speed (a lower bound on the span
between the first and the last arrival, so a slow machine cannot fail it)."""

import json
import signal
import struct
import subprocess
import sys
from pathlib import Path

from harness import check, main, receive_timed, timed_receiver

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


def write_pcap(path, linktype, frames, times_us=None):
    """A pcap file; packet i at times_us[i] microseconds after the first (default: 500 us apart)."""
    with open(path, "wb") as out:
        out.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, linktype))
        for number, frame in enumerate(frames):
            at = times_us[number] if times_us else number * 500
            out.write(struct.pack("<IIII", 1000 + at // 1_000_000, at % 1_000_000, len(frame), len(frame)) + frame)


def two_streams(h, vectors):
    """Two robots' SEND_BUF streams in one capture, to PORT and PORT + 1, 21 frames each over 1 s
    (50 ms apart, the second stream 25 ms after the first): the default replays PORT's, --port the
    other's, each alone, in order and at the capture's spacing divided by --speed."""
    streams = {PORT: vectors[:21], PORT + 1: vectors[21:42]}
    packets, times_us = [], []
    for index in range(21):
        for offset, (port, frames) in enumerate(streams.items()):
            packets.append(bytes(14) + b"\x08\x00" + ipv4(udp(frames[index], port), 2000 + 2 * index + offset))
            times_us.append(index * 50_000 + offset * 25_000)
    capture = h.dir / "two_streams.pcap"
    write_pcap(capture, 113, packets, times_us)
    span_s = 1.0  # from each stream's first frame to its last
    receiver = timed_receiver()
    target = f"127.0.0.1:{receiver.getsockname()[1]}"
    for port, speed, flags in ((PORT, 4, []), (PORT + 1, 1, ["--port", str(PORT + 1)])):
        label = f"replay_port_{port}_speed_{speed}"
        replay = h.start(label, [h.binary("rsg_sim"), "--to", target, "--replay", str(capture), "--speed", str(speed),
                                 *flags])
        received = receive_timed(receiver, len(streams[port]))
        check(h.wait(label, replay, 10) == 0, f"{label} exited {replay.returncode}")
        check([data for _, data in received] == streams[port],
              f"{label}: received {len(received)} datagrams, "
              f"{sum(data in streams[port] for _, data in received)} of them from the stream to port {port}")
        took = received[-1][0] - received[0][0]
        print(f"[{h.name}] {label}: first to last datagram {took:.3f} s", flush=True)
        check(took >= 0.8 * span_s / speed, f"{label}: the capture's {span_s} s took {took:.3f} s at --speed {speed}")
    receiver.close()


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

    receiver = timed_receiver()
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
        # Everything was sent when rsg_sim exited: what has not arrived by then never will.
        received = [data for _, data in receive_timed(receiver, len(frames), timeout_s=0.5)]
        check(received == frames, f"{capture.name}: received {len(received)} datagrams, "
              f"{sum(a == b for a, b in zip(received, frames))} of {len(frames)} as captured")

    # --loop starts over at the end until stopped; SIGINT ends it cleanly.
    looping = h.start("replay_loop", [h.binary("rsg_sim"), "--to", target, "--replay", str(h.dir / "cooked.pcap"),
                                      "--speed", "20", "--loop"])
    received = [data for _, data in receive_timed(receiver, 2 * len(frames) + 5, quiet_s=None)]
    looping.send_signal(signal.SIGINT)
    check(h.wait("replay_loop", looping, 10) == 0, "rsg_sim --loop did not exit 0 on SIGINT")
    check(received == (frames * 3)[:len(received)], "the looped replay is not the capture over and over")

    two_streams(h, vectors)


if __name__ == "__main__":
    sys.exit(main("replay_formats", body))
