#!/usr/bin/env python3
"""Writes the fuzzers' seed corpora, derived from the conformance vectors, into a build folder.

    make_seeds.py VECTORS_DIR OUT_DIR     ->  OUT_DIR/<fuzzer>/<sha1 of the seed>

Idempotent (files are named by content) and standard library only. The corpora are build output,
never committed. A fuzzer without an entry here simply starts from an empty corpus.
"""

import hashlib
import json
import os
import random
import struct
import sys
import zlib


def frame(request, group_select, data_select, data=b""):
    body = bytes([request]) + struct.pack("<H", len(data)) + bytes([group_select, *data_select]) + data
    return body + struct.pack("<I", zlib.crc32(body))


def load(vectors_dir, name):
    with open(os.path.join(vectors_dir, name), encoding="utf-8") as lines:
        return [json.loads(line) for line in lines if line.strip()]


def decode_seeds(valid, invalid):
    return [bytes.fromhex(v["frame_hex"]) for v in valid + invalid]


def json_seeds(valid):
    return [json.dumps(v["decoded"], separators=(",", ":")).encode() for v in valid]


def selection_request_seeds(rng):
    seeds = []
    for group in range(6):
        data_select = [0] * 6
        data_select[group] = 0x0F if group == 5 else 0xFF
        seeds.append(frame(0x30 | group, 1 << group, data_select))
    seeds.append(frame(0x3F, 0x3F, [0xFF] * 5 + [0x0F]))
    seeds.append(frame(0x30, 0, [0] * 6))
    for _ in range(10):
        group_select = rng.randrange(64)
        data_select = [rng.randrange(256) if group_select >> g & 1 else 0 for g in range(6)]
        data_select[5] &= 0x0F
        seeds.append(frame(0x30 | rng.randrange(16), group_select, data_select))
    return seeds


def ipv4(payload, ident=1, flags_offset=0, total_payload=None):
    """An IPv4 header (checksum left 0: readers do not check it) in front of `payload`."""
    return struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(payload), ident, flags_offset, 64, 17, 0,
                       bytes([127, 0, 0, 1]), bytes([127, 0, 0, 1])) + payload


def udp(payload, source_port=40000, destination_port=17000):
    return struct.pack("!HHHH", source_port, destination_port, 8 + len(payload), 0) + payload


def pcap_file(linktype, packets):
    out = struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, linktype)
    for number, packet in enumerate(packets):
        out += struct.pack("<IIII", 1000, number * 1000, len(packet), len(packet)) + packet
    return out


def pcap_seeds(valid):
    """Even first byte: a pcap file (raw IP, Ethernet, Linux cooked); odd: [1][link type][records]."""
    largest = max((bytes.fromhex(v["frame_hex"]) for v in valid), key=len)
    frames = [bytes.fromhex(v["frame_hex"]) for v in valid[:6]] + [largest]
    raw = [ipv4(udp(f)) for f in frames]
    ethernet = [bytes(12) + b"\x08\x00" + p for p in raw]
    cooked = [bytes(14) + b"\x08\x00" + p for p in raw]
    seeds = [b"\x00" + pcap_file(101, raw), b"\x00" + pcap_file(1, ethernet), b"\x00" + pcap_file(113, cooked)]
    # A full frame cut into three IPv4 fragments, as a 1500-byte MTU does, out of order.
    whole = udp(frames[-1])
    pieces = [(0, whole[:1480], 0x2000), (185, whole[1480:2960], 0x2000), (370, whole[2960:], 0)]
    fragments = [ipv4(piece, 7, flag | offset) for offset, piece, flag in pieces]
    records = b"".join(struct.pack("<H", len(f)) + f for f in [fragments[1], fragments[0], fragments[2]])
    seeds.append(b"\x01\x05" + records)  # link type index 5: raw IP
    return seeds


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    vectors_dir, out_dir = sys.argv[1:]
    valid, invalid = load(vectors_dir, "valid.jsonl"), load(vectors_dir, "invalid.jsonl")
    rng = random.Random(2137)  # fixed: the same vectors always give the same seeds
    corpora = {
        "fuzz_decode": decode_seeds(valid, invalid),
        "fuzz_json": json_seeds(valid),
        "fuzz_selection_request": selection_request_seeds(rng),
        "fuzz_pcap": pcap_seeds(valid),
    }
    for fuzzer, seeds in corpora.items():
        folder = os.path.join(out_dir, fuzzer)
        os.makedirs(folder, exist_ok=True)
        for seed in seeds:
            with open(os.path.join(folder, hashlib.sha1(seed).hexdigest()), "wb") as file:
                file.write(seed)
        print(f"{fuzzer}: {len(seeds)} seeds in {folder}")


if __name__ == "__main__":
    main()
