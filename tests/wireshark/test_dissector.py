#!/usr/bin/env python3
"""The Wireshark dissector, run by Debian's tshark (a dissector host rsg did not write), against the
conformance vectors; plus the committed .lua against its generator.

    tests/wireshark/test_dissector.py --generator build/tests/bin/rsg_wireshark_lua [-v]
Standard library only; fails (never skips) when tshark is missing.
"""

import argparse
import json
import math
import re
import struct
import subprocess
import sys
import tempfile
import unittest
import zlib
from pathlib import Path

import pcap_file
import tshark_run

ROOT = Path(__file__).resolve().parents[2]
VECTORS = ROOT / "tests" / "data" / "vectors"
GENERATOR = None
PORT = 17000  # the dissector's default port, the gateway's documented one


def load_jsonl(name):
    return [json.loads(line) for line in (VECTORS / name).read_text().splitlines() if line.strip()]


def invalid_vectors():
    """The delivered invalid vectors, then rsg's own oversized ones (docs/protocol.md, step 1)."""
    return load_jsonl("invalid.jsonl") + load_jsonl("oversized.jsonl")


def table_fields():
    """(name, type) of every field, as the generated dissector's table lists them."""
    text = tshark_run.DISSECTOR.read_text()
    return re.findall(r'\{ name = "(\w+)", index = \d+, group = \d, mask = 0x[0-9a-f]+, type = "(\w+)"', text)


def frame(request, group_select, data_select, data=b""):
    """An independent encoder of header and CRC, for frames the vectors lack."""
    body = bytes([request]) + struct.pack("<H", len(data)) + bytes([group_select, *data_select]) + data
    return body + struct.pack("<I", zlib.crc32(body))


def same_number(text, expected):
    """tshark's text of one float64 element against the canonical JSON's value, bit-exact."""
    if isinstance(expected, str):  # "nan", "inf", "-inf"
        return text == expected
    actual = float(text)
    return actual == expected and math.copysign(1, actual) == math.copysign(1, expected)


class Dissector(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory(prefix="rsg_wireshark_")
        cls.fields = table_fields()
        assert len(cls.fields) == 44, f"the dissector's table has {len(cls.fields)} fields"

    @classmethod
    def tearDownClass(cls):
        cls.dir.cleanup()

    def capture(self, name, datagrams):
        path = Path(self.dir.name) / name
        pcap_file.write(path, datagrams)
        return path

    def test_committed_dissector_is_what_the_generator_writes(self):
        generated = Path(self.dir.name) / "generated.lua"
        subprocess.run([GENERATOR, str(ROOT / "tools/wireshark/rsg_sendbuf.lua.in"), str(generated)], check=True)
        self.assertEqual(generated.read_text(), tshark_run.DISSECTOR.read_text(),
                         "tools/wireshark/rsg_sendbuf.lua is stale: run `cmake --build build --target wireshark-lua`")

    def test_every_valid_vector_decodes_to_its_canonical_json(self):
        vectors = load_jsonl("valid.jsonl")
        capture = self.capture("valid.pcap", [(bytes.fromhex(v["frame_hex"]), 40000, PORT) for v in vectors])
        names = ["sendbuf.packet_number", "sendbuf.length", "sendbuf.group_select", "sendbuf.data_select",
                 "sendbuf.crc_status", "sendbuf.error", "sendbuf.selection_request"]
        names += [f"sendbuf.{name}" for name, _ in self.fields]
        rows = tshark_run.fields(capture, names)
        self.assertEqual(len(rows), len(vectors))
        for number, (row, vector) in enumerate(zip(rows, vectors), start=1):
            with self.subTest(frame=number):
                expected = vector["decoded"]
                self.assertEqual(row["sendbuf.packet_number"], [str(expected["packet_number"])])
                self.assertEqual(row["sendbuf.length"], [str(len(vector["frame_hex"]) // 2 - 14)])
                self.assertEqual([int(x, 0) for x in row["sendbuf.group_select"]], [expected["group_select"]])
                self.assertEqual([int(x, 0) for x in row["sendbuf.data_select"]], expected["data_select"])
                self.assertEqual(row["sendbuf.crc_status"], ["1"])
                self.assertEqual(row["sendbuf.error"], [])
                for name, kind in self.fields:
                    actual = row[f"sendbuf.{name}"]
                    if name not in expected["fields"]:
                        self.assertEqual(actual, [], f"{name} is not in the frame")
                        continue
                    value = expected["fields"][name]
                    if kind == "float64":
                        values = value if isinstance(value, list) else [value]
                        self.assertEqual(len(actual), len(values), name)
                        for text, element in zip(actual, values):
                            self.assertTrue(same_number(text, element), f"{name}: {text} != {element!r}")
                    elif kind == "error_set":
                        self.assertEqual(actual, value, name)
                    else:  # robot_mode, time: integers, exactly
                        self.assertEqual(actual, [str(value)], name)

    def test_every_valid_vector_shows_its_full_precision_joint_positions(self):
        vectors = [v for v in load_jsonl("valid.jsonl") if "q" in v["decoded"]["fields"]]
        self.assertTrue(vectors)
        capture = self.capture("q.pcap", [(bytes.fromhex(v["frame_hex"]), 40000, PORT) for v in vectors])
        argv = [tshark_run.tshark_path(), "-n", "-r", str(capture), "-X", f"lua_script:{tshark_run.DISSECTOR}",
                "-T", "fields", "-e", "sendbuf.q"]
        lines = subprocess.run(argv, capture_output=True, text=True, check=True, env=tshark_run.ENV).stdout.splitlines()
        for line, vector in zip(lines, vectors):
            texts = line.split(",")
            self.assertEqual(len(texts), 7)
            for text, element in zip(texts, vector["decoded"]["fields"]["q"]):
                self.assertTrue(same_number(text, element), f"{text} != {element!r}")

    def test_display_shows_poses_as_rows_units_and_names(self):
        vectors = load_jsonl("valid.jsonl")
        full = next(v for v in vectors if len(v["decoded"]["fields"]) == 44)
        capture = self.capture("full.pcap", [(bytes.fromhex(full["frame_hex"]), 40000, PORT)])
        argv = [tshark_run.tshark_path(), "-n", "-r", str(capture), "-X", f"lua_script:{tshark_run.DISSECTOR}",
                "-O", "sendbuf"]
        text = subprocess.run(argv, capture_output=True, text=True, check=True, env=tshark_run.ENV).stdout
        lines = [line.strip() for line in text.splitlines()]
        fields = full["decoded"]["fields"]
        pose = fields["O_T_EE"]  # column-major: element 4 * column + row
        start = lines.index("O_T_EE (measured end-effector pose in base frame O)")
        for row in range(4):
            shown = lines[start + 1 + row].split(": ")[1].split()
            self.assertEqual([float(x) for x in shown], [pose[4 * column + row] for column in range(4)], row)
        for index, value in enumerate(fields["q"]):
            self.assertIn(f"q[{index}]: {float(value)!r} rad".replace(".0 rad", " rad"), lines)
        self.assertIn(f"time: {fields['time']} ms", lines)
        mode = fields["robot_mode"]
        names = ["other", "idle", "move", "guiding", "reflex", "user_stopped", "automatic_error_recovery"]
        self.assertIn(f"robot_mode: {names[mode]} ({mode})", lines)
        errors = fields["current_errors"]
        self.assertIn("current_errors: " + (", ".join(errors) if errors else "none"), lines)
        self.assertIn("CRC status: Good (1)", [line.strip("[]") for line in lines])

    def test_every_invalid_vector_reports_its_category_as_error_and_expert_info(self):
        vectors = invalid_vectors()
        capture = self.capture("invalid.pcap", [(bytes.fromhex(v["frame_hex"]), 40000, PORT) for v in vectors])
        rows = tshark_run.fields(capture, ["frame.number", "sendbuf.error", "_ws.expert.message"])
        self.assertEqual(len(rows), len(vectors))
        for row, vector in zip(rows, vectors):
            with self.subTest(frame=row["frame.number"], expected=vector["error"]):
                self.assertEqual(row["sendbuf.error"], [vector["error"]])
                self.assertTrue(any(m.startswith(vector["error"] + ": ") for m in row["_ws.expert.message"]),
                                row["_ws.expert.message"])
        # The expert item itself, by its filter name, on exactly the frames of its category.
        for category in sorted({v["error"] for v in vectors}):
            flagged = tshark_run.fields(capture, ["frame.number"], display_filter=f"sendbuf.expert.{category}")
            expected = [str(n) for n, v in enumerate(vectors, start=1) if v["error"] == category]
            self.assertEqual([r["frame.number"][0] for r in flagged], expected, category)

    def test_an_oversized_datagram_cut_by_the_capture_keeps_its_category(self):
        # As the gateway's flight recorder stores one: the first 2137 bytes, the real size in the
        # record header and in the UDP header. The category is the one the gateway counted.
        path = Path(self.dir.name) / "cut.pcap"
        vectors = load_jsonl("oversized.jsonl")
        with open(path, "wb") as out:
            out.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, pcap_file.LINKTYPE_IPV4))
            for number, vector in enumerate(vectors):
                packet = pcap_file.ipv4_udp(bytes.fromhex(vector["frame_hex"]), 40000, PORT)
                kept = packet[:20 + 8 + 2137]
                out.write(struct.pack("<IIII", 1000, number * 1000, len(kept), len(packet)) + kept)
        rows = tshark_run.fields(path, ["sendbuf.error"])
        self.assertEqual([row["sendbuf.error"] for row in rows], [["length_mismatch"]] * len(vectors))

    def test_selection_request_is_flagged_and_keeps_the_decoders_verdict(self):
        request = frame(0x35, 0x04, [0, 0, 0x20, 0, 0, 0])  # asks for q
        empty = frame(0x30, 0, [0] * 6)  # asks for nothing: also a valid, empty state frame
        capture = self.capture("request.pcap", [(request, 40000, PORT), (empty, 40000, PORT)])
        rows = tshark_run.fields(capture, ["sendbuf.selection_request", "sendbuf.error", "sendbuf.packet_number",
                                           "sendbuf.crc_status"])
        self.assertEqual(rows[0]["sendbuf.selection_request"], ["1"])
        self.assertEqual(rows[0]["sendbuf.error"], ["length_mismatch"])
        self.assertEqual(rows[0]["sendbuf.packet_number"], ["5"])
        self.assertEqual(rows[0]["sendbuf.crc_status"], ["1"])
        self.assertEqual((rows[1]["sendbuf.selection_request"], rows[1]["sendbuf.error"]), ([], []))
        flagged = tshark_run.fields(capture, ["frame.number"], display_filter="sendbuf.expert.selection_request")
        self.assertEqual([r["frame.number"] for r in flagged], [["1"]])

    def test_port_preference_moves_the_port_dissector(self):
        valid = bytes.fromhex(load_jsonl("valid.jsonl")[0]["frame_hex"])
        capture = self.capture("ports.pcap", [(valid, 40000, PORT), (valid, 40000, 23456)])
        no_heuristic = ["--disable-heuristic", "sendbuf_udp"]
        for port, claimed in ((PORT, "1"), (23456, "2")):
            rows = self.run_tshark(capture, no_heuristic, [f"sendbuf.port:{port}"])
            self.assertEqual([r["frame.number"] for r in rows if r["sendbuf.packet_number"]], [[claimed]])

    def run_tshark(self, capture, extra_args, options):
        argv = [tshark_run.tshark_path(), "-n", "-r", str(capture), "-X", f"lua_script:{tshark_run.DISSECTOR}",
                *extra_args, "-T", "fields", "-e", "frame.number", "-e", "sendbuf.packet_number"]
        for option in options:
            argv += ["-o", option]
        lines = subprocess.run(argv, capture_output=True, text=True, check=True, env=tshark_run.ENV).stdout.splitlines()
        return [{"frame.number": [n], "sendbuf.packet_number": [p] if p else []}
                for n, p in (line.split("\t") for line in lines)]

    def test_heuristic_claims_frames_on_any_port_and_nothing_else(self):
        valid = [bytes.fromhex(v["frame_hex"]) for v in load_jsonl("valid.jsonl")[:20]]
        request = frame(0x30, 0x24, [0, 0, 0x20, 0, 0, 0x08])
        bad_crc = bytearray(valid[0])
        bad_crc[-1] ^= 0xFF
        rtps = b"RTPS\x02\x03\x01\x0f" + bytes(range(12)) + b"\x15\x05\x00\x10" + bytes(16)
        others = [
            rtps,
            b"\x30\x00\x00" + bytes(11),            # SEND_BUF-like header, CRC wrong
            bytes(bad_crc),                          # a damaged frame off the port: not claimed
            b"\x3f" + bytes(200),                    # length field disagrees with the size
            bytes(14), b"hello, robot", bytes(range(256)) * 8,
        ]
        datagrams = [(f, 40000 + i, 30000 + i) for i, f in enumerate(valid + [request])]
        datagrams += [(f, 50000 + i, 31000 + i) for i, f in enumerate(others)]
        capture = self.capture("heuristic.pcap", datagrams)
        rows = tshark_run.fields(capture, ["frame.number", "sendbuf.packet_number", "rtps"])
        claimed = [int(r["frame.number"][0]) for r in rows if r["sendbuf.packet_number"]]
        self.assertEqual(claimed, list(range(1, len(valid) + 2)))
        self.assertTrue(rows[len(valid) + 1]["rtps"], "tshark's RTPS dissector should keep the RTPS datagram")


def main():
    global GENERATOR
    parser = argparse.ArgumentParser()
    parser.add_argument("--generator", required=True, help="rsg_wireshark_lua")
    args, rest = parser.parse_known_args()
    GENERATOR = args.generator
    tshark_run.tshark_path()
    unittest.main(argv=[sys.argv[0], *rest])


if __name__ == "__main__":
    main()
