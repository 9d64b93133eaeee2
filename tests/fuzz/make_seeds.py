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


def deframer_seeds(valid, invalid, rng):
    """[n][n chunk sizes][stream]: streams of frames, garbage and cut frames under various chunkings."""
    frames = decode_seeds(valid, invalid)
    seeds = [bytes([0]) + b"".join(frames[:20])]
    for _ in range(40):
        stream = b""
        for _ in range(rng.randint(1, 4)):
            stream += rng.randbytes(rng.choice([0, 0, 1, 3, 17]))  # resynchronisation material
            stream += rng.choice(frames)
        stream += rng.choice(frames)[: rng.randint(0, 40)]  # a frame still arriving
        plan = bytes(rng.randrange(256) for _ in range(rng.choice([0, 1, 3, 8])))
        seeds.append(bytes([len(plan)]) + plan + stream)
    return seeds


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


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    vectors_dir, out_dir = sys.argv[1:]
    valid, invalid = load(vectors_dir, "valid.jsonl"), load(vectors_dir, "invalid.jsonl")
    rng = random.Random(2137)  # fixed: the same vectors always give the same seeds
    corpora = {
        "fuzz_decode": decode_seeds(valid, invalid),
        "fuzz_deframer": deframer_seeds(valid, invalid, rng),
        "fuzz_json": json_seeds(valid),
        "fuzz_selection_request": selection_request_seeds(rng),
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
