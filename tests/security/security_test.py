#!/usr/bin/env python3
"""DDS Security tests of rsg: who may read robot_state, and what the wire shows.

Each test makes a fresh test PKI (xml_profiles/security/make_test_pki.sh), runs rsg_secure_probe
publishers and subscribers on a DDS domain of its own, and judges them by the JSON-line events
they report (see secure_probe.cpp). Every wait is bounded, but a bound running out is always a
failure of something that must happen, never a pass: "X never happens" is checked only once a
permitted reader, started after X's would-be culprit, has received everything.

Run by ctest (label `integration`), one test per entry; by hand, as root for the capture tests:
    tests/security/security_test.py --probe build-sec/tests/bin/rsg_secure_probe \\
        --make-pki xml_profiles/security/make_test_pki.sh \\
        --plain-profiles tests/security/plain_udp_profiles.xml --work-dir /tmp/rsg-security \\
        [-v] [Security.test_NAME ...]
A test that cannot test (no CAP_NET_RAW for the capture tests) fails, saying so; nothing is skipped.
Standard library only.
"""

import argparse
import contextlib
import json
import re
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
import unittest
from pathlib import Path

from test_domain import acquire_domain  # noqa: E402

ARGS = None  # the command line, set once by main()

SAMPLES = 20
# How long anything that must happen may take: discovery, the security handshake and the delivery
# of SAMPLES on a loaded CI machine take seconds; this bound only turns a hang into a failure.
DEADLINE_SECONDS = 60

# RTPS port mapping (RTPS 2.x, 9.6.1.1): every port of domain d lies in [7400 + 250 d, + 250).
RTPS_PORT_BASE = 7400
RTPS_DOMAIN_GAIN = 250


class Probe:
    """One rsg_secure_probe process, with the events it has reported so far and its log.

    The probe lives until its standard input closes; stop() closes it, and kills the probe if it
    does not leave in time."""

    def __init__(self, name, mode, profiles, profile, domain, partition, marker=False, topic=None):
        self.name = name
        command = [ARGS.probe, mode, "--profile", profile, "--domain", str(domain), "--partition", partition,
                   "--samples", str(SAMPLES)]
        if topic:
            command += ["--topic", topic]
        for file in profiles:
            command += ["--profiles", str(file)]
        if marker:
            command.append("--marker")
        self._process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                         stderr=subprocess.PIPE, text=True, errors="replace")
        self._events = []
        self._log = []  # Fast DDS's log, uncoloured
        self._finished = False
        self._changed = threading.Condition()
        self._collectors = [threading.Thread(target=self._collect_events, daemon=True),
                            threading.Thread(target=self._collect_log, daemon=True)]
        for collector in self._collectors:
            collector.start()

    def _collect_events(self):
        for line in self._process.stdout:
            with self._changed:
                self._events.append(json.loads(line))
                self._changed.notify_all()
        with self._changed:
            self._finished = True
            self._changed.notify_all()

    def _collect_log(self):
        for line in self._process.stderr:
            with self._changed:
                self._log.append(re.sub(r"\x1b\[[0-9;]*m", "", line.rstrip("\n")))
                self._changed.notify_all()

    def events(self, kind):
        with self._changed:
            return [event for event in self._events if event["event"] == kind]

    def wait_for(self, what, found):
        """Waits until `found(events, log)` returns something true, and returns that."""
        deadline = time.monotonic() + DEADLINE_SECONDS
        with self._changed:
            while not (result := found(self._events, self._log)):
                remaining = deadline - time.monotonic()
                if self._finished or remaining <= 0:
                    reason = f"exited with status {self._process.wait()}" if self._finished else "timed out"
                    raise AssertionError(f"{self.name} {reason} waiting for {what}\n{self.report()}")
                self._changed.wait(remaining)
            return result

    def wait_for_event(self, what, matches):
        """Waits for an event for which `matches(event)` is true, and returns it."""
        return self.wait_for(what, lambda events, _: next(filter(matches, events), None))

    def ready(self):
        """The 'ready' event: the participant exists and its writer or reader was (not) created."""
        return self.wait_for_event("set-up", lambda event: event["event"] == "ready")

    @property
    def participant(self):
        return self.ready()["participant"]

    def wait_for_samples(self, count):
        return self.wait_for(f"{count} samples", lambda events, _: (
            samples if len(samples := [e for e in events if e["event"] == "sample"]) >= count else None))

    def wait_for_authentication(self, participant, status):
        expected = {"event": "authentication", "participant": participant, "status": status}
        return self.wait_for_event(f"{status} authentication of {participant}", lambda event: event == expected)

    def wait_for_log(self, what, text):
        return self.wait_for(what, lambda _, log: next((line for line in log if text in line), None))

    def matched_participants(self):
        return {event["participant"] for event in self.events("matched")}

    def report(self):
        with self._changed:
            events = "\n".join(f"  {json.dumps(event)}" for event in self._events)
            log = "\n".join(f"  {line}" for line in self._log[-30:])
        return f"{self.name} events:\n{events}\n{self.name} log (end):\n{log}"

    def stop(self):
        with contextlib.suppress(BrokenPipeError):
            self._process.stdin.close()
        try:
            self._process.wait(timeout=15)
        except subprocess.TimeoutExpired:
            self._process.kill()
            self._process.wait()
        for collector in self._collectors:
            collector.join()
        self._process.stdout.close()
        self._process.stderr.close()


class UdpCapture:
    """Collects the payload of every IPv4 UDP datagram sent to a port range while in a `with`.

    A packet socket sees what crosses a network interface, without a tool or a new package; it
    needs root (CAP_NET_RAW). It listens on every interface: datagrams between local addresses
    cross `lo` whichever address they go to, and multicast also appears on the interface it
    leaves by."""

    ETH_P_IP = 0x0800
    SOL_PACKET = 263
    PACKET_STATISTICS = 6

    def __init__(self, ports):
        self.ports = ports
        self.payloads = []
        self.dropped = None
        self._stop = threading.Event()
        self._thread = None
        # SOCK_DGRAM: the kernel strips the link-layer header, so every packet starts with IPv4.
        self._socket = socket.socket(socket.AF_PACKET, socket.SOCK_DGRAM, socket.htons(self.ETH_P_IP))

    def __enter__(self):
        self._socket.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 16 << 20)
        self._socket.settimeout(0.1)  # how often the capture looks at _stop
        self._drop_count()  # reading the statistics resets them
        self._thread = threading.Thread(target=self._capture, name="capture", daemon=True)
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()
        self.dropped = self._drop_count()
        self._socket.close()

    def _capture(self):
        while not self._stop.is_set():
            try:
                packet = self._socket.recv(65536)
            except socket.timeout:
                continue
            if (payload := self._udp_payload(packet)) is not None:
                self.payloads.append(payload)

    def _udp_payload(self, packet):
        if len(packet) < 20 or packet[0] >> 4 != 4 or packet[9] != socket.IPPROTO_UDP:
            return None
        header_bytes = (packet[0] & 0x0F) * 4
        if len(packet) < header_bytes + 8:
            return None  # a later fragment; RTPS between local addresses never fragments (lo's MTU is 64 kB)
        (destination_port,) = struct.unpack_from("!H", packet, header_bytes + 2)
        return packet[header_bytes + 8:] if destination_port in self.ports else None

    def _drop_count(self):
        _, drops = struct.unpack("II", self._socket.getsockopt(self.SOL_PACKET, self.PACKET_STATISTICS, 8))
        return drops

    def occurrences(self, pattern):
        return sum(payload.count(pattern) for payload in self.payloads)


def make_pki(directory):
    """A fresh test PKI with UDP-only participant profiles; returns the profiles file."""
    done = subprocess.run([ARGS.make_pki, "--udp-only", str(directory)], capture_output=True, text=True,
                          timeout=60, check=False)
    if done.returncode != 0:
        raise AssertionError(f"make_test_pki.sh failed ({done.returncode}):\n{done.stderr}")
    return Path(done.stdout.strip())


def utc_days_from_now(days):
    return time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime(time.time() + days * 86400))


def run_openssl(*args):
    subprocess.run(["openssl", *args], capture_output=True, timeout=60, check=True)


def forge_permissions(pki, forged):
    """What an intruder with a genuine identity could try next: a grant to read robot_state for its
    own subject, signed by a CA of its own making, which its own participant then trusts as the
    permissions CA. Returns a profiles file with that participant, rsg_forged_intruder."""
    forged.mkdir()
    run_openssl("genpkey", "-algorithm", "EC", "-pkeyopt", "ec_paramgen_curve:P-256", "-out", forged / "ca.key")
    # The genuine CA's name: names are not what Fast DDS verifies.
    run_openssl("req", "-x509", "-new", "-key", forged / "ca.key", "-sha256", "-days", "30",
                "-subj", "/O=rsg test/CN=rsg test CA", "-addext", "basicConstraints=critical,CA:TRUE",
                "-addext", "keyUsage=critical,keyCertSign,digitalSignature", "-out", forged / "ca.pem")
    subject = subprocess.run(["openssl", "x509", "-in", pki / "intruder.pem", "-noout", "-subject", "-nameopt",
                              "RFC2253"], capture_output=True, text=True, check=True).stdout
    # The reader's grant, which includes robot_state, made out to the intruder.
    grant = (Path(ARGS.make_pki).parent / "permissions_reader.xml.in").read_text(encoding="utf-8")
    for placeholder, value in (("SUBJECT", subject.strip().removeprefix("subject=")),
                               ("NOT_BEFORE", utc_days_from_now(-1)), ("NOT_AFTER", utc_days_from_now(30))):
        grant = grant.replace(f"@{placeholder}@", value)
    (forged / "permissions.xml").write_text(grant, encoding="utf-8")
    # Its participant verifies the governance with the forged CA too, so it signs a copy of that.
    templates = Path(ARGS.make_pki).parent
    for name, document in (("permissions", forged / "permissions.xml"),
                           ("governance", templates / "governance.xml")):
        run_openssl("smime", "-sign", "-text", "-in", document, "-out", forged / f"{name}.p7s",
                    "-signer", forged / "ca.pem", "-inkey", forged / "ca.key")

    profiles = (pki / "rsg_secure_profiles.xml").read_text(encoding="utf-8")
    intruder = re.search(r'<participant profile_name="rsg_secure_intruder">.*?</participant>', profiles, re.S)[0]
    forger = intruder.replace('"rsg_secure_intruder"', '"rsg_forged_intruder"')
    for name, file in (("permissions_ca", "ca.pem"), ("permissions", "permissions.p7s"),
                       ("governance", "governance.p7s")):
        forger = re.sub(rf"(<name>dds\.sec\.access\.builtin\.Access-Permissions\.{name}</name>\s*<value>)[^<]*",
                        lambda match, file=file: match[1] + f"file://{forged / file}", forger)
    transports = re.search(r"<transport_descriptors>.*?</transport_descriptors>", profiles, re.S)[0]
    (forged / "profiles.xml").write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">\n'
        f"  <profiles>\n    {transports}\n    {forger}\n  </profiles>\n</dds>\n", encoding="utf-8")
    return forged / "profiles.xml"


class Security(unittest.TestCase):
    def setUp(self):
        # A domain of its own (tests/support/test_domain.py), so that ctest may run the tests in
        # parallel; a new one per test, so that running them all in one process reuses none either.
        self.domain = acquire_domain()
        Path(ARGS.work_dir).mkdir(parents=True, exist_ok=True)
        self.work = Path(self.enterContext(tempfile.TemporaryDirectory(
            dir=ARGS.work_dir, prefix=f"{self._testMethodName}-")))
        # A named partition, as with `rsg_gateway --partition robot1`: Fast DDS grants a partition
        # only when the permissions name it (the templates say "*").
        self.partition = "robot1"
        self.pki = self.work / "pki"
        self.secure_profiles = make_pki(self.pki)

    def start(self, name, mode, profile, profiles=None, marker=False, topic=None):
        probe = Probe(name, mode, profiles or [self.secure_profiles], profile, self.domain, self.partition,
                      marker, topic)
        self.addCleanup(probe.stop)
        return probe

    def gateway(self, marker=False):
        """The publisher, as the gateway identity."""
        gateway = self.start("gateway", "publish", "rsg_secure_gateway", marker=marker)
        self.assertTrue(gateway.ready()["endpoint_created"], gateway.report())
        return gateway

    def permitted_reader(self, marker=False):
        reader = self.start("reader", "subscribe", "rsg_secure_reader", marker=marker)
        self.assertTrue(reader.ready()["endpoint_created"], reader.report())
        return reader

    def assert_receives_every_sample_exactly(self, reader):
        samples = reader.wait_for_samples(SAMPLES)
        self.assertEqual([(sample["index"], sample["exact"]) for sample in samples],
                         [(index, True) for index in range(SAMPLES)], reader.report())

    def assert_kept_out(self, outsider, gateway, reader):
        """Once the permitted reader has everything, the outsider has nothing and matched nothing,
        and the gateway matched the permitted reader alone."""
        self.assert_receives_every_sample_exactly(reader)
        self.assertEqual(outsider.events("sample"), [], outsider.report())
        self.assertEqual(outsider.events("matched"), [], outsider.report())
        self.assertEqual(gateway.matched_participants(), {reader.participant}, gateway.report())

    def test_permitted_reader_receives_exact_samples(self):
        gateway = self.gateway()
        reader = self.permitted_reader()
        self.assert_receives_every_sample_exactly(reader)
        self.assertEqual(gateway.matched_participants(), {reader.participant}, gateway.report())
        self.assertEqual(reader.matched_participants(), {gateway.participant}, reader.report())

    def test_permitted_reader_in_the_default_partition_receives_exact_samples(self):
        self.partition = ""  # the gateway's default
        self.test_permitted_reader_receives_exact_samples()

    def test_unauthenticated_participant_is_not_matched(self):
        gateway = self.gateway()
        plain = self.start("plain", "subscribe", "rsg_plain_udp", profiles=[ARGS.plain_profiles])
        self.assertTrue(plain.ready()["endpoint_created"], plain.report())
        # The gateway saw the plain participant and turned it away: what follows is a refusal, not
        # a participant that was never there.
        gateway.wait_for_authentication(plain.participant, "unauthorized")
        self.assert_kept_out(plain, gateway, self.permitted_reader())

    # docs/security.md, "What an attacker on the network can and cannot do": a participant without
    # a certificate can neither write robot_state or rsg_gateway_status nor read them. Its writers
    # carry the marker, so any of its samples that got through would not be exact.
    def plain(self, name, mode, topic):
        probe = self.start(name, mode, "rsg_plain_udp", profiles=[ARGS.plain_profiles], marker=True, topic=topic)
        self.assertTrue(probe.ready()["endpoint_created"], probe.report())
        return probe

    def test_unauthenticated_writer_of_robot_state_is_not_matched(self):
        gateway = self.gateway()
        forger = self.plain("forger", "publish", "robot_state")
        gateway.wait_for_authentication(forger.participant, "unauthorized")
        reader = self.permitted_reader()
        self.assert_kept_out(forger, gateway, reader)
        self.assertEqual(reader.matched_participants(), {gateway.participant}, reader.report())
        self.assertTrue(all(sample["exact"] for sample in reader.events("sample")), reader.report())

    def status_endpoint(self, name, mode, profile):
        """A secure probe on rsg_gateway_status: the gateway identity publishes it, the intruder
        identity may subscribe it (with RobotState's type, as the forger's)."""
        probe = self.start(name, mode, profile, topic="rsg_gateway_status")
        self.assertTrue(probe.ready()["endpoint_created"], probe.report())
        return probe

    def test_unauthenticated_writer_of_gateway_status_is_not_matched(self):
        # The same type as the genuine writer's, so that only security, not a type mismatch, keeps
        # the forger out.
        status = self.status_endpoint("gateway", "publish", "rsg_secure_gateway")
        forger = self.plain("forger", "publish", "rsg_gateway_status")
        status.wait_for_authentication(forger.participant, "unauthorized")
        monitor = self.status_endpoint("monitor", "subscribe", "rsg_secure_intruder")
        self.assert_kept_out(forger, status, monitor)
        self.assertEqual(monitor.matched_participants(), {status.participant}, monitor.report())
        self.assertTrue(all(sample["exact"] for sample in monitor.events("sample")), monitor.report())

    def test_unauthenticated_reader_of_gateway_status_is_not_matched(self):
        status = self.status_endpoint("gateway", "publish", "rsg_secure_gateway")
        eavesdropper = self.plain("eavesdropper", "subscribe", "rsg_gateway_status")
        status.wait_for_authentication(eavesdropper.participant, "unauthorized")
        self.assert_kept_out(eavesdropper, status, self.status_endpoint("monitor", "subscribe", "rsg_secure_intruder"))

    def test_open_domain_lets_anyone_write_gateway_status(self):
        # The control: without DDS Security, a participant writes rsg_gateway_status (here with
        # RobotState's layout) and any reader of that topic and type takes it as the gateway's.
        forger = self.start("forger", "publish", "rsg_plain_udp", profiles=[ARGS.plain_profiles],
                            topic="rsg_gateway_status")
        reader = self.start("reader", "subscribe", "rsg_plain_udp", profiles=[ARGS.plain_profiles],
                            topic="rsg_gateway_status")
        self.assert_receives_every_sample_exactly(reader)
        self.assertEqual(reader.matched_participants(), {forger.participant}, reader.report())

    def test_intruder_without_read_permission_is_refused(self):
        gateway = self.gateway()
        intruder = self.start("intruder", "subscribe", "rsg_secure_intruder")
        # Fast DDS checks the grant before it creates a reader: create_datareader returns null
        # ("robot_state topic not found in allow rule"), though the identity itself is valid.
        self.assertFalse(intruder.ready()["endpoint_created"], intruder.report())
        gateway.wait_for_authentication(intruder.participant, "authorized")
        self.assert_kept_out(intruder, gateway, self.permitted_reader())

    def test_forged_permissions_are_rejected(self):
        gateway = self.gateway()
        forged_profiles = forge_permissions(self.pki, self.work / "forged")
        forger = self.start("forger", "subscribe", "rsg_forged_intruder", profiles=[forged_profiles])
        # Its own participant trusts the forged grant and creates the reader; the gateway does not.
        # Fast DDS 2.9 reports that refusal in its log only, not to the participant's listener.
        self.assertTrue(forger.ready()["endpoint_created"], forger.report())
        gateway.wait_for_log("the forged permissions to be refused",
                             f"Error validating remote permissions for {forger.participant}")
        self.assert_kept_out(forger, gateway, self.permitted_reader())
        self.assertNotIn(forger.participant, {event["participant"] for event in gateway.events("authentication")
                                              if event["status"] == "authorized"}, gateway.report())

    def capture_delivery(self, publisher_profile, subscriber_profile, profiles):
        """Captures the domain's traffic while samples full of the marker go from a publisher to a
        subscriber; returns the capture and the marker's bytes."""
        ports = range(RTPS_PORT_BASE + RTPS_DOMAIN_GAIN * self.domain,
                      RTPS_PORT_BASE + RTPS_DOMAIN_GAIN * (self.domain + 1))
        try:
            capture = UdpCapture(ports)
        except PermissionError:
            self.fail("cannot test what crosses the wire: capturing packets needs root (CAP_NET_RAW); "
                      "run the test as root or give the Python interpreter CAP_NET_RAW")
        with capture:
            publisher = self.start("publisher", "publish", publisher_profile, profiles=profiles, marker=True)
            subscriber = self.start("subscriber", "subscribe", subscriber_profile, profiles=profiles, marker=True)
            # Everything has crossed the wire once the subscriber holds every sample, exact.
            self.assert_receives_every_sample_exactly(subscriber)
        self.assertEqual(capture.dropped, 0, "the capture lost packets: its verdict would mean nothing")
        self.assertTrue(capture.payloads, f"no UDP traffic to ports {ports.start}..{ports.stop - 1} captured")
        return capture, bytes.fromhex(publisher.ready()["marker"])

    def test_wire_carries_no_plaintext(self):
        capture, marker = self.capture_delivery("rsg_secure_gateway", "rsg_secure_reader", [self.secure_profiles])
        self.assertEqual(capture.occurrences(marker), 0,
                         f"the marker {marker.hex()} crossed the wire in clear despite encryption")

    def test_wire_carries_plaintext_without_security(self):
        # The control of the test above: the same exchange without security shows the marker, so
        # a capture that finds none is evidence of encryption, not of a capture that missed it.
        capture, marker = self.capture_delivery("rsg_plain_udp", "rsg_plain_udp", [ARGS.plain_profiles])
        self.assertGreater(capture.occurrences(marker), 0, f"the marker {marker.hex()} not found in clear")


def main():
    global ARGS
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--probe", required=True, help="the rsg_secure_probe executable")
    parser.add_argument("--make-pki", required=True, help="xml_profiles/security/make_test_pki.sh")
    parser.add_argument("--plain-profiles", required=True, help="tests/security/plain_udp_profiles.xml")
    parser.add_argument("--work-dir", required=True, help="where each test makes its PKI (removed after)")
    ARGS, unittest_args = parser.parse_known_args()
    result = unittest.main(argv=[sys.argv[0], *unittest_args], exit=False).result
    sys.exit(0 if result.wasSuccessful() and not result.skipped else 1)


if __name__ == "__main__":
    main()
