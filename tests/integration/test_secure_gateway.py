"""The secure deployment docs/security.md shows, end to end: rsg_gateway and rsg_echo with the test PKI's
participant profiles. The authenticated, permitted reader gets every frame exactly; a plain
rsg_echo on the same domain, started first, is never matched and prints nothing. The gateway reads
its private key as under systemd's LoadCredential=: its profile names
file://${CREDENTIALS_DIRECTORY}/gateway.key, and CREDENTIALS_DIRECTORY is where the key is; without
that variable the same profile is refused at start (exit 2, naming the property)."""

import os
import sys

from harness import check, main, read_json, read_json_lines, wait_for_stats, wait_reader_matched, free_udp_port

COUNT = 200
RATE = "200"


def body(h):
    profiles = h.secure_profiles()
    # The gateway's key moved where systemd would put it, and its profile pointing there.
    credentials = h.dir / "credentials"
    credentials.mkdir(mode=0o700)
    (h.dir / "pki" / "gateway.key").rename(credentials / "gateway.key")
    secure = profiles / "rsg_secure_profiles.xml"
    key_path = f"file://{h.dir / 'pki' / 'gateway.key'}"
    check(key_path in secure.read_text(), f"no {key_path} in the test PKI's profiles")
    secure.write_text(secure.read_text().replace(key_path, "file://${CREDENTIALS_DIRECTORY}/gateway.key"))
    port = free_udp_port()
    flags = ["--listen", f"127.0.0.1:{port}", "--profiles", str(profiles), "--participant-profile", "rsg_secure_gateway"]

    os.environ.pop("CREDENTIALS_DIRECTORY", None)
    refused, _ = h.gateway("refused", *flags)
    check(h.wait("refused", refused) == 2, "a profile naming ${CREDENTIALS_DIRECTORY} without it did not exit 2")
    error = (h.dir / "refused.err").read_text()
    check("dds.sec.auth.builtin.PKI-DH.private_key: names ${CREDENTIALS_DIRECTORY}, but CREDENTIALS_DIRECTORY is "
          "not set" in error, f"the refusal does not name the property: {error}")

    os.environ["CREDENTIALS_DIRECTORY"] = str(credentials)
    try:
        gateway, stats = h.gateway("gateway", *flags)
    finally:
        del os.environ["CREDENTIALS_DIRECTORY"]
    wait_for_stats(stats, lambda s: True, "the secure gateway to start")

    echo = [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "robot_state", "--json"]
    plain = h.start("plain_echo", echo)
    secure = h.start("secure_echo", [*echo, "--profiles", str(profiles), "--participant-profile",
                                     "rsg_secure_reader", "--count", str(COUNT), "--timeout", "45"])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, "the secure reader to match the gateway's writer",
                   timeout_s=40)
    wait_reader_matched(h, "secure_echo", "rsg_echo")  # a volatile reader misses what comes before it

    record = h.dir / "sim.record.jsonl"
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", RATE, "--count", str(COUNT),
                           "--record", str(record)])
    check(status == 0, f"rsg_sim exited {status}")
    check(h.wait("secure_echo", secure, 45) == 0, "the secure reader did not receive every sample")
    sent = read_json_lines(record)
    received = read_json_lines(h.output("secure_echo"))
    check(len(sent) == COUNT and received == sent,
          f"the secure reader got {len(received)} samples for {len(sent)} frames, or other values")

    # The plain reader started before the secure one, which has everything by now.
    check(read_json(stats)["state_readers"] == 1, f"the gateway matched other readers: {read_json(stats)}")
    check(h.stop("plain_echo", plain) == 0, "the plain rsg_echo did not exit 0 on SIGTERM")
    check(h.output("plain_echo").read_text() == "", "the plain, unauthenticated rsg_echo received samples")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("secure_gateway", body))
