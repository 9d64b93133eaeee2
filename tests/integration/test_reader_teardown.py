"""A reader with the gateway's egress profile is deleted at once, whatever payload waits for it.

Fast DDS (2.9.1, 2.14.5 and 3.1.2 alike, the three this test runs on; eProsima/Fast-DDS#6490,
merged July 2026, in no release yet) can hang in `delete_datareader` for a data-sharing reader that
holds a writer's payload it did not accept: the delete joins the reader's data-sharing listener
thread, which spins and never returns. Seen in `integration.egress_limits`: the egress gateway
still deleting its reader 20 s after SIGTERM, one core spinning in
`DataSharingListener::process_new_data`. The egress reader's profile (`rsg_state_reader`,
xml_profiles/gateway.xml) now turns data-sharing off.

The writer is rsg_gateway's (data-sharing on, as its profile says): 20 frames from rsg_sim, then no
more, so nothing overwrites a refused payload. The reader (rsg_reader_teardown_probe) has the
egress reader's profile with room for 4 samples, refuses the rest, and is deleted: as shipped, the
delete must return; with data-sharing forced on (the control, which shows the hang is real on this
build), it must not.
"""

import sys

from harness import check, free_udp_port, main, wait_for, wait_for_stats

# Seconds a delete may take; one that returns takes milliseconds.
WAIT_S = 8


def delete_refusing_reader(h, port, stats, label, *flags):
    """Runs the probe until its delete returned or hung; its exit status and last line."""
    probe = h.start(label, [h.binary("rsg_reader_teardown_probe"), "--domain", str(h.domain),
                            "--profile", "rsg_state_reader", "--wait", str(WAIT_S), *flags])
    out = h.output(label)
    wait_for(lambda: "matched" in out.read_text() or probe.poll() is not None, f"{label} to match the writer")
    check(probe.poll() is None, f"{label} exited {probe.poll()} before its reader matched: {out.read_text()}")
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, f"the gateway's writer to match {label}")
    check(h.run(f"sim_{label}", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000",
                                 "--count", "20"]) == 0, "rsg_sim failed")
    status = h.wait(label, probe, timeout_s=WAIT_S + 40)
    said = out.read_text().strip().splitlines()
    print(f"[reader_teardown] {label}: exit {status}: {said[-1] if said else ''}", flush=True)
    wait_for_stats(stats, lambda s: s["state_readers"] == 0, f"{label}'s reader to leave")
    return status, said[-1] if said else ""


def body(h):
    port = free_udp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}")
    shipped = delete_refusing_reader(h, port, stats, "as_shipped")
    control = delete_refusing_reader(h, port, stats, "data_sharing_on", "--data-sharing", "on")
    check(shipped[0] == 0, f"the egress reader's profile as shipped: the delete did not return: {shipped}")
    # If the control returns, this build has the upstream fix (or the reader refused nothing): the
    # test no longer shows what it says, so it fails until revisited.
    check(control[0] == 3, f"the control (data-sharing on) did not hang: {control}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")


if __name__ == "__main__":
    sys.exit(main("reader_teardown", body))
