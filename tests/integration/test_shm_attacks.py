"""A local process's shared memory cannot stop a gateway run with --data-sharing off (docs/security.md,
"Same-host processes").

A same-host data-sharing reader creates a segment in /dev/shm that the writers it matches open and
trust. Any local user can run such a reader and then put in its segment's place a well-formed
Boost.Interprocess segment whose "notification_node" has the wrong size (rsg_shm_forge):

1. control, --data-sharing auto (rsg's profiles as they are): the gateway opens it when it matches
   the reader and Fast DDS 2.9.1 aborts on a Boost.Interprocess assertion (priv_generic_find). If
   this lane fails, Fast DDS no longer trusts the segment and docs/security.md must say so;
2. --data-sharing off: the gateway never opens it, stays up, publishes at 1 kHz, the same reader
   gets its samples over UDP, and SIGTERM ends the gateway with exit 0.

Runs where Fast DDS 2.9's segment layout is the one rsg_shm_forge makes (make test)."""

import sys
import time
from pathlib import Path

from harness import check, main, wait_for, wait_for_stats, free_udp_port

SAMPLES = 500


def datasharing_segments(pid):
    """The fast_datasharing_* files of /dev/shm that process `pid` has mapped."""
    names = set()
    for line in Path(f"/proc/{pid}/maps").read_text().splitlines():
        path = line.split()[-1] if len(line.split()) >= 6 else ""
        if path.startswith("/dev/shm/fast_datasharing_"):
            names.add(path[len("/dev/shm/"):])
    return names


def forged_reader(h, label):
    """A data-sharing reader (rsg_echo's default QoS, reader_realtime) whose segment is then forged."""
    reader = h.start(label, [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "robot_state",
                             "--count", str(SAMPLES), "--timeout", "30"])
    segments = wait_for(lambda: datasharing_segments(reader.pid), f"{label}'s data-sharing segment")
    for name in segments:
        check(h.run(label + "_forge", [h.binary("rsg_shm_forge"), name]) == 0, f"could not forge {name}")
    return reader


def body(h):
    # 1. The control: rsg's profiles as they are.
    reader = forged_reader(h, "reader_auto")
    gateway, _ = h.gateway("gateway_auto", "--data-sharing", "auto", "--listen", f"127.0.0.1:{free_udp_port()}")
    wait_for(lambda: gateway.poll() is not None, "the gateway with --data-sharing auto to open the forged segment",
             timeout_s=20)
    err = (h.dir / "gateway_auto.err").read_text(errors="replace")
    check(gateway.returncode != 0 and "priv_generic_find" in err,
          f"the control did not abort (exit {gateway.returncode}): Fast DDS no longer trusts a peer's segment, "
          "docs/security.md must say so")
    reader.kill()
    reader.wait()

    # 2. --data-sharing off: the same attack.
    port = free_udp_port()
    reader = forged_reader(h, "reader_off")
    gateway, stats = h.gateway("gateway_off", "--data-sharing", "off", "--listen", f"127.0.0.1:{port}",
                               "--expected-rate", "1000")
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, "the gateway to match the forged reader")
    time.sleep(1.0)  # a reader found by discovery is matched and its segment opened at once
    check(gateway.poll() is None, f"the gateway with --data-sharing off died (exit {gateway.returncode})")
    h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--duration", "5"])
    check(h.wait("reader_off", reader, 30) == 0, f"the reader did not get {SAMPLES} samples over UDP")
    check(gateway.poll() is None, f"the gateway with --data-sharing off died (exit {gateway.returncode})")
    check(not datasharing_segments(gateway.pid), "the gateway with --data-sharing off maps a data-sharing segment")
    check(h.stop("gateway_off", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("shm_attacks", body))
