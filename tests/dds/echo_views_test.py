#!/usr/bin/env python3
"""Multi-process group views: rsg_echo processes on different views of one mixed-selection
stream each print exactly the samples carrying all their groups, as canonical JSON identical to
what was published; and rsg_echo's exit codes.

The stream comes from the test publisher (rsg_views_publish), or, with --sim and --gateway, from
rsg_sim through rsg_gateway. Python 3 standard library only.
"""
import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import unittest

from harness import free_udp_port, test_domain, wait_for_stats  # noqa: E402

ARGS = None

# (echo arguments, groups a sample must all carry; 0 = every sample)
VIEWS = [
    (["--view", "view_joints"], 0b000100),
    (["--view", "view_forces"], 0b001100),
    (["--view", "view_kinematics"], 0b000101),
    (["--groups", "3,5"], 0b101000),
    (["--view", "view_full"], 0b111111),
    ([], 0),
]


def echo(*extra, partition="views_test", stdout=subprocess.PIPE):
    """Starts rsg_echo. A whole stream of JSON overflows a pipe that nobody reads while the test
    waits for the publisher, so long outputs go to a file (`stdout`)."""
    command = [ARGS.echo, "--domain", str(test_domain()), "--topic", "robot_state", "--partition", partition,
               *extra]
    return subprocess.Popen(command, stdout=stdout, stderr=subprocess.PIPE, text=True)


def wanted(records, groups):
    return [line for line in records if json.loads(line)["group_select"] & groups == groups]


def wait_echo_matched(process, consumed):
    """Reads `process`'s stderr until rsg_echo says its reader matched one writer. The writer's side
    of discovery is not enough: a volatile reader that learns of the writer later misses what was
    sent in between. Lines read are kept in `consumed` for the test's messages; an echo that exits
    first (its --timeout) ends the wait at end of file."""
    for line in process.stderr:
        consumed.append(line)
        if line.startswith("rsg_echo: matched 1 writer of "):
            return
    raise AssertionError("rsg_echo exited before its reader matched the writer: " + "".join(consumed))


class EchoViews(unittest.TestCase):
    def check_views(self, start_stream, records_file):
        """Starts one rsg_echo per view, then the stream; each must print exactly its subset.
        `start_stream(readers, echoes_matched)` starts the stream once the writer has matched the
        readers and `echoes_matched()` has returned (each reader has matched the writer)."""
        # The expected counts are known only once the stream is recorded, so each echo runs
        # until the stream ends (--timeout) rather than for --count samples.
        with tempfile.TemporaryDirectory() as tmp:
            echoes = []
            for index, (view_args, groups) in enumerate(VIEWS):
                output = open(os.path.join(tmp, f"echo{index}.jsonl"), "w+")
                echoes.append((echo(*view_args, "--json", "--timeout", "5", stdout=output), output, view_args,
                               groups, []))

            def echoes_matched():
                for process, _, _, _, consumed in echoes:
                    wait_echo_matched(process, consumed)

            stream = start_stream(len(echoes), echoes_matched)
            _, stream_err = stream.communicate(timeout=300)
            self.assertEqual(stream.returncode, 0, stream_err)
            with open(records_file) as f:
                records = f.read().splitlines()
            self.assertGreater(len(records), 0)
            for process, output, view_args, groups, consumed in echoes:
                _, err = process.communicate(timeout=60)
                err = "".join(consumed) + err
                output.seek(0)
                printed = output.read().splitlines()
                output.close()
                with self.subTest(view=view_args):
                    self.assertEqual(process.returncode, 1, "expected the idle timeout after the stream: " + err)
                    expected = wanted(records, groups)
                    self.assertGreater(len(expected), 0, "the stream does not exercise this view")
                    # Same text: both sides print with rsg's canonical JSON writer.
                    self.assertEqual(printed, expected)

    def test_views_of_the_test_publisher_stream(self):
        with tempfile.TemporaryDirectory() as tmp:
            record = os.path.join(tmp, "published.jsonl")

            def start(readers, echoes_matched):
                # The publisher waits for its side of discovery, then for the go on stdin.
                publisher = subprocess.Popen(
                    [ARGS.publish, "--domain", str(test_domain()), "--topic", "robot_state",
                     "--partition", "views_test", "--readers", str(readers), "--count", "256",
                     "--rate", "1000", "--record", record, "--wait-for-go"],
                    stdin=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                echoes_matched()
                publisher.stdin.write("go\n")
                publisher.stdin.flush()
                return publisher

            self.check_views(start, record)

    def test_views_of_the_sim_stream_through_the_gateway(self):
        port = free_udp_port()
        with tempfile.TemporaryDirectory() as tmp:
            stats = os.path.join(tmp, "gateway.json")
            gateway = subprocess.Popen(
                [os.environ["RSG_GATEWAY"], "--listen", f"127.0.0.1:{port}", "--domain", str(test_domain()),
                 "--topic", "robot_state", "--partition", "views_test", "--stats-file", stats],
                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            try:
                record = os.path.join(tmp, "sent.jsonl")

                def start(readers, echoes_matched):
                    # Both sides of discovery before the robot starts.
                    wait_for_stats(stats, lambda s: s["state_readers"] >= readers, f"{readers} readers to match the gateway")
                    echoes_matched()
                    return subprocess.Popen(
                        [os.environ["RSG_SIM"], "--to", f"127.0.0.1:{port}", "--rate", "1000", "--count", "2000",
                         "--every", "1:g2", "--every", "3:g3", "--every", "10:g0,g5", "--every", "50:all",
                         "--record", record],
                        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)

                self.check_views(start, record)
            finally:
                gateway.send_signal(signal.SIGINT)
                gateway.communicate(timeout=30)

    def test_count_then_exit_0(self):
        with tempfile.TemporaryDirectory() as tmp:
            process = echo("--view", "view_joints", "--json", "--count", "5", "--timeout", "60")
            publisher = subprocess.run(
                [ARGS.publish, "--domain", str(test_domain()), "--topic", "robot_state", "--partition",
                 "views_test", "--readers", "1", "--count", "64", "--record", os.path.join(tmp, "r.jsonl")],
                capture_output=True, text=True, timeout=120)
            out, err = process.communicate(timeout=60)
            self.assertEqual(process.returncode, 0, err)
            self.assertEqual(len(out.splitlines()), 5)
            self.assertNotEqual(publisher.returncode, 2)

    def test_idle_timeout_exits_1(self):
        process = echo("--timeout", "1", partition="nobody_publishes_here")
        _, err = process.communicate(timeout=60)
        self.assertEqual(process.returncode, 1)
        self.assertIn("no sample", err)

    def test_sigint_exits_0(self):
        process = echo("--view", "view_status", partition="nobody_publishes_here")
        # Its first table ("waiting for samples") comes from its wait loop, once SIGINT is its stop
        # request: a signal sent earlier (a slow start, e.g. through the Fast DDS 3 chroot's wrapper)
        # would find the default action or, in a background job, SIGINT ignored.
        self.assertTrue(process.stdout.readline().startswith("rsg_echo"))
        process.send_signal(signal.SIGINT)
        process.communicate(timeout=30)
        self.assertEqual(process.returncode, 0)

    def test_usage_errors_exit_2(self):
        cases = {
            "unknown view": ["--view", "view_no_such_thing"],
            "not a view": ["--view", "reader_logger"],
            "bad group": ["--groups", "2,9"],
            "view and groups": ["--view", "view_joints", "--groups", "2"],
            "unknown qos": ["--qos", "no_such_profile"],
            "unknown participant profile": ["--participant-profile", "no_such_participant"],
            "unknown option": ["--frobnicate"],
        }
        for name, extra in cases.items():
            with self.subTest(name):
                process = echo(*extra, "--timeout", "5")
                _, err = process.communicate(timeout=60)
                self.assertEqual(process.returncode, 2, err)
                self.assertTrue(err.strip(), "no message on stderr")


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--echo", required=True)
    parser.add_argument("--publish", required=True)
    ARGS, rest = parser.parse_known_args()
    # Never a skip: a run without the gateway would pass without its stream's views being checked.
    missing = [name for name in ("RSG_SIM", "RSG_GATEWAY") if not os.environ.get(name)]
    if missing:
        sys.exit(f"echo_views_test.py: {' and '.join(missing)} not set: the paths of rsg_sim and rsg_gateway "
                 "(ctest sets them; by hand: RSG_SIM=build/bin/rsg_sim RSG_GATEWAY=build/bin/rsg_gateway)")
    unittest.main(argv=[sys.argv[0], *rest])
