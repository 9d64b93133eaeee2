#!/usr/bin/env python3
"""The RTPS screen (src/dds/rtps_screen.cpp) fuzzed against a parser that is not rsg's: Wireshark's
RTPS dissector, through Debian's tshark.

1. Seeds: rsg's own traffic, captured from loopback by dumpcap while a gateway at 1 kHz serves a
   plain rsg_echo and a view reader (SPDP, SEDP with type information and content-filter
   properties, user DATA, HEARTBEAT, ACKNACK, GAP). Every seed must pass the screen whole: the
   screen refuses nothing a real rsg peer sends.
2. Mutants: structure-aware changes of the seeds (submessage lengths, fixed fields, parameter
   lengths and counts, DATA turned into DATA_FRAG or GAP with chosen numbers, truncations,
   splices), MUTANTS of them, each screened by rsg_rtps_screen_probe.
3. The oracle: tshark reads what the screen hands on (a pcap of the forwarded bytes) and must find
   no malformed packet and no expert error in it. The control: the same mutants unscreened, where
   tshark must find malformed packets (the mutants are broken in ways the oracle sees), and the
   screen must have refused some of them.

    tests/wireshark/test_rtps_screen.py --bin build/bin --test-bin build/tests/bin
"""

import random
import signal
import struct
import subprocess
import sys

from harness import check, main, wait_for, wait_for_stats, free_udp_port  # noqa: E402

import pcap_file  # noqa: E402
import tshark_run  # noqa: E402

MUTANTS = 6000
SEED = 46
INTERESTING32 = [0, 1, 2, 3, 4, 7, 8, 16, 28, 0x7F, 0xFF, 0x100, 0xFFFF, 0x10000, 0x7FFFFFFF, 0x80000000,
                 0xFFFFFFFE, 0xFFFFFFFF]
INTERESTING16 = [0, 1, 2, 3, 4, 8, 12, 16, 20, 27, 28, 29, 32, 0x7FFF, 0x8000, 0xFFFF]
RTPS_PORT = 7400  # what the oracle's pcap sends every datagram to: tshark decodes it as RTPS


def submessages(datagram):
    """(offset, id, flags, length, body) of each submessage Fast DDS would walk."""
    out, at = [], 20
    while len(datagram) - at >= 4:
        identifier, flags = datagram[at], datagram[at + 1]
        little = flags & 1
        length = struct.unpack_from("<H" if little else ">H", datagram, at + 2)[0]
        body = at + 4
        if body + length > len(datagram):
            break
        if length == 0 and identifier not in (0x01, 0x09):
            length = len(datagram) - body
        out.append((at, identifier, flags, length, body))
        at = body + ((length + 3) & ~3)
    return out


def put32(buffer, at, value, little):
    if at + 4 <= len(buffer):
        struct.pack_into("<I" if little else ">I", buffer, at, value & 0xFFFFFFFF)


def put16(buffer, at, value, little):
    if at + 2 <= len(buffer):
        struct.pack_into("<H" if little else ">H", buffer, at, value & 0xFFFF)


def parameters(datagram, body, length):
    """Offsets of the parameter headers of a DATA's serialized parameter list (PL_CDR_LE/BE)."""
    payload = body + 20
    if payload + 4 > body + length or datagram[payload + 1] not in (2, 3):
        return [], True
    little = datagram[payload + 1] == 3
    out, at = [], payload + 4
    while at + 4 <= body + length:
        pid, plen = struct.unpack_from("<HH" if little else ">HH", datagram, at)
        out.append(at)
        if pid == 1:
            break
        at += 4 + ((plen + 3) & ~3)
    return out, little


def as_data_frag(datagram, sm, rng):
    """The DATA `sm` rewritten as a DATA_FRAG with chosen fragment numbers and sizes."""
    at, _, flags, length, body = sm
    little = flags & 1
    fixed = datagram[body + 4:body + 20]  # readerId, writerId, writerSN
    payload = datagram[body + 20:body + length]
    fragment_size = rng.choice([1, 2, 3, 4, 8, 100, 1000, max(len(payload), 1), 0xFFFF])
    sample_size = rng.choice([len(payload), len(payload) + 1, len(payload) + 2, fragment_size * 2 + rng.randrange(4),
                              0xFFFFFFFF, rng.randrange(1, 70000)])
    first = rng.choice([0, 1, 2, 3, 1000, 0xFFFFFFFF])
    count = rng.choice([0, 1, 2, 1000, 0xFFFF])
    to_qos = rng.choice([28, 28, 28, 12, 60, 0xFFFF])
    end = "<" if little else ">"
    new_body = struct.pack(end + "HH", 0, to_qos) + fixed + struct.pack(end + "IHHI", first, count, fragment_size,
                                                                         sample_size)
    new_body += payload[:rng.choice([len(payload), 4, 0, fragment_size])]
    submessage = bytes([0x16, flags & ~0x02 | 0x04]) + struct.pack(end + "H", len(new_body)) + new_body
    return datagram[:at] + submessage + datagram[body + ((length + 3) & ~3):]


def as_gap(datagram, sm, rng):
    at, _, flags, length, body = sm
    little = flags & 1
    end = "<" if little else ">"
    ids = datagram[body + 4:body + 12] if len(datagram) >= body + 12 else bytes(8)
    start = rng.choice([0, 1, 2, 1 << 31, 1 << 32])
    base = start + rng.choice([0, 1, 255, 1 << 16, 1 << 20, (1 << 32) - 1, -1])
    bits = rng.choice([0, 1, 32, 256, 257, 0xFFFFFFFF])
    words = min((bits + 31) // 32, 8) if rng.random() < 0.8 else 0
    new_body = ids + struct.pack(end + "iIiII", start >> 32, start & 0xFFFFFFFF, base >> 32, base & 0xFFFFFFFF,
                                 bits) + bytes(4 * words)
    return datagram[:at] + bytes([0x08, flags & 1]) + struct.pack(end + "H", len(new_body)) + new_body + \
        datagram[body + ((length + 3) & ~3):]


def mutate(seeds, rng):
    datagram = bytearray(rng.choice(seeds))
    walk = submessages(datagram)
    if not walk:
        return bytes(datagram)
    sm = rng.choice(walk)
    at, identifier, flags, length, body = sm
    little = flags & 1
    kind = rng.randrange(9)
    if kind == 0:  # a submessage's length
        put16(datagram, at + 2, rng.choice(INTERESTING16 + [length + 4, max(length - 4, 0)]), little)
    elif kind == 1 and length >= 4:  # a 32-bit field of the body
        put32(datagram, body + 4 * rng.randrange(length // 4), rng.choice(INTERESTING32), little)
    elif kind == 2 and length >= 2:  # a 16-bit field of the body
        put16(datagram, body + 2 * rng.randrange(min(length // 2, 16)), rng.choice(INTERESTING16), little)
    elif kind in (3, 4) and identifier == 0x15:  # a parameter's length, or its first word (a count)
        offsets, pl_little = parameters(datagram, body, length)
        if offsets:
            param = rng.choice(offsets)
            if kind == 3:
                put16(datagram, param + 2, rng.choice(INTERESTING16), pl_little)
            else:
                put32(datagram, param + 4, rng.choice(INTERESTING32), pl_little)
    elif kind == 5 and identifier == 0x15 and length >= 20:
        return as_data_frag(bytes(datagram), sm, rng)
    elif kind == 6 and length >= 12:
        return as_gap(bytes(datagram), sm, rng)
    elif kind == 7:  # truncated
        return bytes(datagram[:rng.randrange(20, len(datagram) + 1)])
    else:  # another datagram's submessages spliced in
        other = rng.choice(seeds)
        return bytes(datagram) + other[20:]
    return bytes(datagram)


def screen(h, datagrams):
    """(forward_bytes, cut, reason) of each datagram, from rsg_rtps_screen_probe."""
    done = subprocess.run([h.binary("rsg_rtps_screen_probe")], input="".join(d.hex() + "\n" for d in datagrams),
                          capture_output=True, text=True, timeout=120)
    check(done.returncode == 0, f"rsg_rtps_screen_probe exited {done.returncode}: {done.stderr}")
    rows = [line.split() for line in done.stdout.splitlines()]
    check(len(rows) == len(datagrams), f"the probe answered {len(rows)} of {len(datagrams)} datagrams")
    return [(int(size), cut, reason) for size, cut, reason in rows]


def flagged(h, name, datagrams):
    """Frame numbers (1-based) tshark's RTPS dissector finds malformed or with an expert error in."""
    capture = h.dir / f"{name}.pcap"
    pcap_file.write(capture, [(d, 40000, RTPS_PORT) for d in datagrams])
    rows = tshark_run.fields(capture, ["frame.number", "_ws.expert.message"],
                             display_filter="_ws.malformed || _ws.expert.severity == error",
                             options=[], dissector=tshark_run.DISSECTOR)
    return {int(r["frame.number"][0]): r["_ws.expert.message"] for r in rows}


def capture_seeds(h):
    """rsg's own RTPS traffic: a gateway at 1 kHz, a plain reader and a view reader."""
    first = 7400 + 250 * h.domain
    capture = h.dir / "seeds.pcapng"
    dumpcap = h.start("dumpcap", ["dumpcap", "-q", "-i", "lo", "-f", f"udp and portrange {first}-{first + 249}",
                                  "-w", str(capture)])
    wait_for(lambda: capture.exists() and capture.stat().st_size > 0, "dumpcap to start capturing")
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", "1000")
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    readers = [h.start(name, [h.binary("rsg_echo"), "--domain", str(h.domain), "--json", "--count", "300",
                              "--timeout", "30", *extra])
               for name, extra in (("plain", []), ("view", ["--view", "view_joints"]))]
    wait_for_stats(stats, lambda s: s["state_readers"] >= 2, "both readers to match the gateway")
    check(h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--duration", "1"]) == 0,
          "rsg_sim failed")
    for name, reader in zip(("plain", "view"), readers):
        check(h.wait(name, reader, 40) == 0, f"rsg_echo ({name}) did not get its samples")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")
    dumpcap.send_signal(signal.SIGINT)
    check(h.wait("dumpcap", dumpcap, 10) == 0, "dumpcap did not finish the capture")
    rows = tshark_run.fields(capture, ["udp.payload"], display_filter="udp")
    seeds = sorted({bytes.fromhex(r["udp.payload"][0].replace(":", "")) for r in rows if r["udp.payload"]})
    check(len(seeds) > 50, f"the capture holds only {len(seeds)} distinct datagrams")
    kinds = {sm[1] for s in seeds for sm in submessages(s)}
    check({0x15, 0x07, 0x06} <= kinds, f"the capture lacks DATA, HEARTBEAT or ACKNACK (ids {sorted(kinds)})")
    return seeds


def body(h):
    for tool in ("dumpcap", "tshark"):
        check(subprocess.run(["which", tool], capture_output=True).returncode == 0,
              f"{tool} is not installed (docker/packages/test.txt lists tshark; run `make deps`)")
    seeds = capture_seeds(h)
    verdicts = screen(h, seeds)
    refused = [(s, v) for s, v in zip(seeds, verdicts) if v[1] not in ("none", "trailing")]
    check(not refused, f"the screen refused {len(refused)} of {len(seeds)} datagrams of rsg's own traffic, e.g. "
          f"{refused[0][1] if refused else ''}: {refused[0][0].hex() if refused else ''}")
    seed_flags = flagged(h, "seeds", seeds)
    check(not seed_flags, f"tshark flags rsg's own traffic: {sorted(seed_flags.items())[:3]}")
    print(f"[rtps_screen] {len(seeds)} datagrams of rsg's own traffic pass the screen whole", flush=True)

    rng = random.Random(SEED)
    mutants = [mutate(seeds, rng) for _ in range(MUTANTS)]
    verdicts = screen(h, mutants)
    reasons = {}
    for _, cut, reason in verdicts:
        if cut == "invalid":
            reasons[reason] = reasons.get(reason, 0) + 1
    forwarded = [m[:size] for m, (size, _, _) in zip(mutants, verdicts) if size > 20]
    control = flagged(h, "unscreened", mutants)
    print(f"[rtps_screen] {MUTANTS} mutants: {len(forwarded)} handed on (some shortened), refused by reason "
          f"{dict(sorted(reasons.items()))}; tshark flags {len(control)} of the unscreened", flush=True)
    check(len(control) > MUTANTS // 50, f"the control: tshark flags only {len(control)} unscreened mutants "
          "(the mutants are not broken in ways the oracle sees)")
    check(sum(reasons.values()) > MUTANTS // 10, f"the screen refused only {sum(reasons.values())} mutants")
    after = flagged(h, "screened", forwarded)
    check(not after, f"tshark flags {len(after)} datagrams the screen handed on: "
          + "; ".join(f"{msgs} in {forwarded[n - 1].hex()}" for n, msgs in sorted(after.items())[:3]))


if __name__ == "__main__":
    sys.exit(main("rtps_screen", body))
