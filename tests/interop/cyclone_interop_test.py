#!/usr/bin/env python3
"""Interop with Cyclone DDS 0.10: RobotState samples cross between rsg (Fast DDS 2.9) and Cyclone
programs built from the same IDL by idlc, in both directions, with every value intact (compared
as rsg's canonical JSON text, so -0.0, NaN and all 64 bits of `time` count).

With RSG_GATEWAY set, also: samples a Cyclone application publishes on the gateway's egress topic
leave the gateway as valid frames carrying the same values. Python 3 standard library only.
"""
import argparse
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest

from test_domain import test_domain, test_port  # noqa: E402  (a DDS domain, and ports, this test alone holds)

ARGS = None
TOPIC = "robot_state"
PARTITION = "interop"


class CycloneInterop(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)

    def path(self, name):
        return os.path.join(self.tmp.name, name)

    def publish_with_rsg(self, readers, count=256):
        """The mixed-selection stream from rsg's Fast DDS test publisher; returns its records."""
        record = self.path("rsg_published.jsonl")
        result = subprocess.run(
            [ARGS.rsg_publish, "--domain", str(test_domain()), "--topic", TOPIC, "--partition", PARTITION,
             "--readers", str(readers), "--count", str(count), "--rate", "1000", "--record", record],
            capture_output=True, text=True, timeout=300)
        self.assertEqual(result.returncode, 0, result.stderr)
        with open(record) as f:
            return f.read().splitlines()

    def test_cyclone_subscriber_receives_rsg_samples_exactly(self):
        count = 256
        cyclone = subprocess.Popen(
            [ARGS.cyclone_echo, str(test_domain()), TOPIC, PARTITION, str(count), "60"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        published = self.publish_with_rsg(readers=1, count=count)
        out, err = cyclone.communicate(timeout=120)
        self.assertEqual(cyclone.returncode, 0, err)
        self.assertEqual(out.splitlines(), published)

    def test_rsg_receives_cyclone_samples_exactly_including_views(self):
        # The samples: rsg's mixed-selection stream (every group subset), as its publisher records
        # it; the publisher waits for a reader, so a throwaway rsg_echo plays that part.
        source = self.path("source.jsonl")
        recorder = subprocess.Popen(
            [ARGS.rsg_echo, "--domain", str(test_domain()), "--topic", TOPIC, "--partition", PARTITION,
             "--json", "--count", "128", "--timeout", "60"],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        records = self.publish_with_rsg(readers=1, count=128)
        recorder.communicate(timeout=60)
        with open(source, "w") as f:
            f.write("\n".join(records) + "\n")

        outputs = {}
        echoes = {}
        for name, extra in {"all": [], "forces": ["--view", "view_forces"]}.items():
            outputs[name] = open(self.path(f"rsg_{name}.jsonl"), "w+")
            echoes[name] = subprocess.Popen(
                [ARGS.rsg_echo, "--domain", str(test_domain()), "--topic", TOPIC, "--partition", PARTITION,
                 "--json", "--timeout", "5", *extra],
                stdout=outputs[name], stderr=subprocess.PIPE, text=True)
        publisher = subprocess.run(
            [ARGS.cyclone_publish, str(test_domain()), TOPIC, PARTITION, str(len(echoes)), source],
            capture_output=True, text=True, timeout=300)
        self.assertEqual(publisher.returncode, 0, publisher.stderr)
        expected = {
            "all": records,
            "forces": [r for r in records if json.loads(r)["group_select"] & 0b001100 == 0b001100],
        }
        for name, process in echoes.items():
            _, err = process.communicate(timeout=60)
            outputs[name].seek(0)
            printed = outputs[name].read().splitlines()
            outputs[name].close()
            with self.subTest(reader=name):
                self.assertEqual(process.returncode, 1, "expected the idle timeout after the stream: " + err)
                self.assertEqual(printed, expected[name])

    def test_gateway_egress_turns_cyclone_samples_into_frames(self):
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sink:
            sink.bind(("127.0.0.1", 0))
            sink.settimeout(30)
            sink_port = sink.getsockname()[1]
            listen_port = test_port()
            gateway = subprocess.Popen(
                [os.environ["RSG_GATEWAY"], "--listen", f"127.0.0.1:{listen_port}", "--domain", str(test_domain()),
                 "--topic", "robot_state_in", "--partition", PARTITION, "--egress-topic", TOPIC,
                 "--send-to", f"127.0.0.1:{sink_port}"],
                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            try:
                records = [json.dumps({"packet_number": i % 16, "group_select": 36,
                                       "data_select": [0, 0, 32, 0, 0, 8],
                                       "fields": {"q": [0.1 * i, -0.0, 1e-300, 2.5, -3.0, 4.0, 5.0], "time": 2 ** 63 + i}},
                                      separators=(",", ":")) for i in range(20)]
                source = self.path("egress.jsonl")
                with open(source, "w") as f:
                    f.write("\n".join(records) + "\n")
                publisher = subprocess.run(
                    [ARGS.cyclone_publish, str(test_domain()), TOPIC, PARTITION, "1", source],
                    capture_output=True, text=True, timeout=300)
                self.assertEqual(publisher.returncode, 0, publisher.stderr)
                for expected in records:
                    frame, _ = sink.recvfrom(4096)
                    decoded = subprocess.run([os.environ["RSG_FRAME"], "decode"], input=frame,
                                             capture_output=True, timeout=30)
                    self.assertEqual(decoded.returncode, 0, decoded.stderr)
                    self.assertEqual(json.loads(decoded.stdout), json.loads(expected))
            finally:
                gateway.send_signal(signal.SIGINT)
                gateway.wait(timeout=30)


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--cyclone-echo", required=True)
    parser.add_argument("--cyclone-publish", required=True)
    parser.add_argument("--rsg-echo", required=True)
    parser.add_argument("--rsg-publish", required=True)
    ARGS, rest = parser.parse_known_args()
    # Never a skip: a run without the gateway would pass without its egress being checked.
    missing = [name for name in ("RSG_GATEWAY", "RSG_FRAME") if not os.environ.get(name)]
    if missing:
        sys.exit(f"cyclone_interop_test.py: {' and '.join(missing)} not set: the paths of rsg_gateway and "
                 "rsg_frame (ctest sets them; by hand: RSG_GATEWAY=build/bin/rsg_gateway RSG_FRAME=build/bin/rsg_frame)")
    unittest.main(argv=[sys.argv[0], *rest])
