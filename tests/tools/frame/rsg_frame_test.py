#!/usr/bin/env python3
"""End-to-end tests of the rsg_frame command line against the conformance vectors.

Run by ctest (label `cli`); by hand:
    tests/tools/frame/rsg_frame_test.py --tool build/bin/rsg_frame --vectors tests/data/vectors [-v]
Standard library only.
"""

import argparse
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import unittest
import zlib

TOOL = None
VECTORS = None


def load_jsonl(name):
    with open(os.path.join(VECTORS, name), encoding="utf-8") as lines:
        return [json.loads(line) for line in lines if line.strip()]


def invalid_vectors():
    """The delivered invalid vectors, then rsg's own oversized ones (docs/protocol.md, step 1)."""
    return load_jsonl("invalid.jsonl") + load_jsonl("oversized.jsonl")


def run(*args, stdin=b""):
    """Runs the tool; returns (exit status, stdout bytes, stderr text)."""
    done = subprocess.run([TOOL, *args], input=stdin, capture_output=True, timeout=60, check=False)
    return done.returncode, done.stdout, done.stderr.decode()


def same_value(actual, expected):
    """JSON equality by value as docs/protocol.md asks (8.0 == 8), except that -0.0 keeps its sign
    and objects must list their keys in the same order (fields in field-index order)."""
    if isinstance(expected, dict):
        return (isinstance(actual, dict) and list(actual) == list(expected)
                and all(same_value(actual[key], expected[key]) for key in expected))
    if isinstance(expected, list):
        return (isinstance(actual, list) and len(actual) == len(expected)
                and all(same_value(a, e) for a, e in zip(actual, expected)))
    if isinstance(expected, (int, float)) and not isinstance(expected, bool):
        return (isinstance(actual, (int, float)) and not isinstance(actual, bool) and actual == expected
                and math.copysign(1, actual) == math.copysign(1, expected))
    return actual == expected


def frame(request, group_select, data_select, data=b""):
    """An independent encoder of the header and CRC trailer, for frames the vectors lack."""
    body = bytes([request]) + struct.pack("<H", len(data)) + bytes([group_select, *data_select]) + data
    return body + struct.pack("<I", zlib.crc32(body))


class Decode(unittest.TestCase):
    def assert_same(self, actual, expected):
        self.assertTrue(same_value(actual, expected), f"\n  got      {actual}\n  expected {expected}")

    def decode_hex_lines(self, vectors):
        """Decodes every vector's frame_hex in one --hex-lines run: one JSON object per vector."""
        status, out, err = run("decode", "--hex-lines",
                               stdin="".join(v["frame_hex"] + "\n" for v in vectors).encode())
        self.assertEqual((status, err), (0, ""))
        lines = out.decode().splitlines()
        self.assertEqual(len(lines), len(vectors))
        return [json.loads(line) for line in lines]

    def test_hex_lines_decode_every_valid_vector_by_value(self):
        vectors = load_jsonl("valid.jsonl")
        for decoded, vector in zip(self.decode_hex_lines(vectors), vectors):
            self.assert_same(decoded, vector["decoded"])

    def test_hex_lines_report_the_category_of_every_invalid_vector(self):
        vectors = invalid_vectors()
        for report, vector in zip(self.decode_hex_lines(vectors), vectors):
            self.assertEqual(list(report), ["error", "message"])
            self.assertEqual(report["error"], vector["error"])
            self.assertTrue(report["message"])

    def test_hex_lines_skip_blank_lines_and_accept_crlf_and_upper_case(self):
        valid = load_jsonl("valid.jsonl")[0]
        invalid = load_jsonl("invalid.jsonl")[0]
        text = f"\n{valid['frame_hex'].upper()}\r\n   \n\t{invalid['frame_hex']}  \n\n"
        status, out, _ = run("decode", "--hex-lines", stdin=text.encode())
        self.assertEqual(status, 0)
        lines = out.decode().splitlines()
        self.assertEqual(len(lines), 2)
        self.assert_same(json.loads(lines[0]), valid["decoded"])
        self.assertEqual(json.loads(lines[1])["error"], invalid["error"])

    def test_hex_lines_name_the_line_and_the_fault_of_malformed_hex(self):
        good = load_jsonl("valid.jsonl")[0]["frame_hex"]
        text = f'{good}\n\n30z0\n{good[:-1]}\n"quoted"\n'
        status, out, _ = run("decode", "--hex-lines", stdin=text.encode())
        self.assertEqual(status, 0)
        reports = [json.loads(line) for line in out.decode().splitlines()]
        self.assertEqual(len(reports), 4)
        self.assertNotIn("error", reports[0])
        self.assertEqual(reports[1], {"error": "bad_hex", "message": "line 3: byte 0x7a at column 3 is not a hex digit"})
        self.assertEqual(reports[2]["error"], "bad_hex")
        self.assertTrue(reports[2]["message"].startswith("line 4: odd number of hex digits"))
        self.assertEqual(reports[3]["error"], "bad_hex")
        self.assertTrue(reports[3]["message"].startswith("line 5: byte 0x22 at column 1"))

    def test_binary_frame_from_a_file(self):
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "frame.bin")
            for vector in load_jsonl("valid.jsonl"):
                with open(path, "wb") as file:
                    file.write(bytes.fromhex(vector["frame_hex"]))
                status, out, err = run("decode", path)
                self.assertEqual((status, err), (0, ""))
                self.assertTrue(out.endswith(b"\n"))
                self.assert_same(json.loads(out), vector["decoded"])

    def test_binary_frame_from_standard_input(self):
        vector = load_jsonl("valid.jsonl")[-1]
        for args in (["decode"], ["decode", "-"]):
            status, out, _ = run(*args, stdin=bytes.fromhex(vector["frame_hex"]))
            self.assertEqual(status, 0)
            self.assert_same(json.loads(out), vector["decoded"])

    def test_invalid_binary_frame_exits_1_with_its_category(self):
        for vector in invalid_vectors():
            status, out, err = run("decode", stdin=bytes.fromhex(vector["frame_hex"]))
            self.assertEqual((status, out), (1, b""))
            self.assertTrue(err.startswith(f"error: {vector['error']}: "), err)

    def test_empty_input_is_a_truncated_frame(self):
        status, _, err = run("decode", stdin=b"")
        self.assertEqual(status, 1)
        self.assertTrue(err.startswith("error: truncated: "), err)


class Encode(unittest.TestCase):
    def test_hex_lines_encode_every_valid_vector_byte_for_byte(self):
        vectors = load_jsonl("valid.jsonl")
        status, out, err = run("encode", "--hex-lines",
                               stdin="".join(json.dumps(v["decoded"]) + "\n" for v in vectors).encode())
        self.assertEqual((status, err), (0, ""))
        self.assertEqual(out.decode().splitlines(), [v["frame_hex"].lower() for v in vectors])

    def test_binary_output_is_the_frames_back_to_back(self):
        vectors = load_jsonl("valid.jsonl")
        status, out, _ = run("encode", stdin="".join(json.dumps(v["decoded"]) + "\n" for v in vectors).encode())
        self.assertEqual(status, 0)
        self.assertEqual(out, b"".join(bytes.fromhex(v["frame_hex"]) for v in vectors))

    def test_reads_a_file_and_its_own_decoder_output(self):
        vectors = load_jsonl("valid.jsonl")
        _, decoded, _ = run("decode", "--hex-lines", stdin="".join(v["frame_hex"] + "\n" for v in vectors).encode())
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "frames.jsonl")
            with open(path, "wb") as file:
                file.write(decoded)
            status, out, _ = run("encode", "--hex-lines", path)
        self.assertEqual(status, 0)
        self.assertEqual(out.decode().splitlines(), [v["frame_hex"].lower() for v in vectors])

    def test_malformed_json_stops_at_its_line(self):
        first = json.dumps(load_jsonl("valid.jsonl")[0]["decoded"])
        status, out, err = run("encode", "--hex-lines", stdin=f'{first}\n\n{{"packet_number": 1,\n{first}\n'.encode())
        self.assertEqual(status, 1)
        self.assertEqual(len(out.decode().splitlines()), 1)  # the line before the error was written
        self.assertTrue(err.startswith("error: line 3: malformed JSON"), err)

    def test_number_beyond_double_range_is_malformed_json(self):
        # Found by fuzz_json: the JSON library reports it as out_of_range, not as a parse error.
        text = '{"packet_number":0,"group_select":32,"data_select":[0,0,0,0,0,2],"fields":{"control_command_success_rate":1e999}}'
        status, out, err = run("encode", stdin=text.encode())
        self.assertEqual((status, out), (1, b""))
        self.assertTrue(err.startswith("error: line 1: malformed JSON: "), err)

    def test_object_that_does_not_describe_a_frame(self):
        cases = {
            '{"packet_number":0,"group_select":4,"data_select":[0,0,32,0,0,0],"fields":{"qq":[]}}':
                "error: line 1: fields: 'qq' is not a field name",
            '{"packet_number":16,"group_select":0,"data_select":[0,0,0,0,0,0],"fields":{}}':
                "error: line 1: packet_number",
            '[1,2]': "error: line 1: expected a JSON object",
        }
        for text, message in cases.items():
            status, out, err = run("encode", stdin=text.encode())
            self.assertEqual((status, out), (1, b""), text)
            self.assertTrue(err.startswith(message), err)

    def test_object_the_decoder_would_reject_is_not_encoded(self):
        cases = {
            '{"packet_number":0,"group_select":32,"data_select":[0,0,0,0,0,4],"fields":{"robot_mode":7}}':
                "error: line 1: cannot encode: bad_value: ",
            '{"packet_number":0,"group_select":0,"data_select":[0,0,32,0,0,0],"fields":{"q":[0,0,0,0,0,0,0]}}':
                "error: line 1: cannot encode: selection_mismatch: ",
        }
        for text, message in cases.items():
            status, out, err = run("encode", stdin=text.encode())
            self.assertEqual((status, out), (1, b""), text)
            self.assertTrue(err.startswith(message), err)


class Request(unittest.TestCase):
    def test_groups_select_every_field_of_each_group(self):
        status, out, _ = run("request", "--groups", "2")
        self.assertEqual(status, 0)
        self.assertEqual(out, frame(0x30, 0x04, [0, 0, 0xFF, 0, 0, 0]))
        status, out, _ = run("request", "--groups", "0,5", "--packet-number", "7", "--hex")
        self.assertEqual(status, 0)
        self.assertEqual(out.decode(), frame(0x37, 0x21, [0xFF, 0, 0, 0, 0, 0x0F]).hex() + "\n")

    def test_fields_select_exactly_those_fields(self):
        status, out, _ = run("request", "--fields", "q,dq,time", "--hex-lines")
        self.assertEqual(status, 0)
        self.assertEqual(bytes.fromhex(out.decode()), frame(0x30, 0x24, [0, 0, 0xA0, 0, 0, 0x08]))

    def test_a_state_decoder_rejects_a_non_empty_request(self):
        _, request, _ = run("request", "--fields", "q")
        status, _, err = run("decode", stdin=request)
        self.assertEqual(status, 1)
        self.assertTrue(err.startswith("error: length_mismatch: "), err)

    def test_decode_says_a_request_is_one_and_what_it_asks_for(self):
        _, request, _ = run("request", "--groups", "2", "--packet-number", "5")
        status, out, err = run("decode", stdin=request)
        self.assertEqual((status, out), (1, b""))
        lines = err.splitlines()
        self.assertEqual(len(lines), 2, err)
        self.assertTrue(lines[0].startswith("error: length_mismatch: "), err)
        note = "note: these bytes are a selection request (gateway -> robot), not a state frame (robot -> gateway): "
        self.assertTrue(lines[1].startswith(note), err)
        self.assertEqual(json.loads(lines[1][len(note):]),
                         {"packet_number": 5, "group_select": 4, "data_select": [0, 0, 255, 0, 0, 0],
                          "fields": ["delbow_c", "ddelbow_c", "tau_J", "tau_J_d", "dtau_J", "q", "q_d", "dq"]})
        # One hex line per record: the error keeps its category and carries the request.
        _, hex_request, _ = run("request", "--fields", "q,time", "--hex")
        status, out, _ = run("decode", "--hex-lines", stdin=hex_request)
        self.assertEqual(status, 0)
        line = json.loads(out)
        self.assertEqual(line["error"], "length_mismatch")
        self.assertEqual(line["selection_request"]["fields"], ["q", "time"])

    def test_bad_selections_are_usage_errors(self):
        for args in (["--groups", "6"], ["--fields", "q,nope"], ["--groups", "1", "--fields", "q"], [],
                     ["--groups", "1", "--packet-number", "16"]):
            status, out, err = run("request", *args)
            self.assertEqual((status, out), (2, b""), args)
            self.assertTrue(err, args)


class ExitStatus(unittest.TestCase):
    def test_usage_errors_exit_2(self):
        for args in ([], ["frobnicate"], ["decode", "--no-such-option"], ["decode", "a", "b"],
                     ["encode", "--hex-lines", "a", "b"]):
            status, out, err = run(*args)
            self.assertEqual((status, out), (2, b""), args)
            self.assertTrue(err, args)

    def test_help_exits_0(self):
        for args in (["--help"], ["decode", "--help"], ["request", "--help"]):
            status, out, _ = run(*args)
            self.assertEqual(status, 0, args)
            self.assertIn(b"Usage", out)

    def test_unreadable_input_exits_2(self):
        for command in (["decode"], ["decode", "--hex-lines"], ["encode"]):
            status, out, err = run(*command, "/nonexistent/frames")
            self.assertEqual((status, out), (2, b""), command)
            self.assertTrue(err.startswith("rsg_frame: cannot open '/nonexistent/frames'"), err)


def main():
    global TOOL, VECTORS
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tool", required=True, help="path of the rsg_frame executable")
    parser.add_argument("--vectors", required=True, help="folder holding valid.jsonl and invalid.jsonl")
    args, unittest_args = parser.parse_known_args()
    TOOL, VECTORS = os.path.abspath(args.tool), args.vectors
    unittest.main(argv=[sys.argv[0], *unittest_args])


if __name__ == "__main__":
    main()
