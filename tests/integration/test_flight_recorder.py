"""The gateway's flight recorder (--pcap-ring --pcap-dir): when the robot falls silent the gateway
writes the last second of datagrams as a pcap file, and again on SIGUSR1. Read by Debian's tshark
(with rsg's dissector), the file holds exactly the newest datagrams the simulator sent (its own
--pcap says which), oldest first, invalid ones included (a datagram longer than any frame cut to
2137 bytes), spanning at most the configured second. A thread of its own writes the file: with that
thread stopped (as on a hung disk) the gateway goes on publishing; /metrics counts each dump by
how it ended (rsg_flight_recorder_dumps_total)."""

import re
import signal
import subprocess
import sys
import time
from pathlib import Path

from harness import check, main, read_json, wait_for, wait_for_stats, free_udp_port
from metrics_support import free_tcp_port, http_get
from thread_freeze import freeze_thread, thaw_thread, thread_named

DISSECTOR = Path(__file__).resolve().parents[2] / "tools" / "wireshark" / "rsg_sendbuf.lua"
RATE = 500
COUNT = 1500  # three seconds of frames against a one-second ring


def read_capture(path):
    """(time, payload hex, sendbuf.error) per UDP datagram, as tshark reads them."""
    done = subprocess.run(["tshark", "-n", "-r", str(path), "-X", f"lua_script:{DISSECTOR}", "-T", "fields",
                           "-e", "frame.time_epoch", "-e", "udp.payload", "-e", "sendbuf.error"],
                          capture_output=True, text=True, timeout=60)
    check(done.returncode == 0, f"tshark cannot read {path.name}: {done.stderr}")
    return [tuple(line.split("\t")) for line in done.stdout.splitlines()]


def dump_counts(metrics_port):
    """rsg_flight_recorder_dumps_total by result, from the gateway's /metrics."""
    reply = http_get(metrics_port, "/metrics")
    found = re.findall(r'^rsg_flight_recorder_dumps_total\{.*result="(\w+)"\} (\d+)$', reply[1] if reply else "", re.M)
    return {result: int(value) for result, value in found}


def stuck_dump_writer(h, gateway, stats, port, dumps):
    """A dump never holds up the ingress: with the thread that writes dumps stuck (as on a hung
    disk), SIGUSR1 is still taken at once and frames keep being published; two dumps wait, a third
    is refused with an error line, and once the thread runs again the two are written."""
    writer = wait_for(lambda: thread_named(gateway.pid, "rsg-dump"), "the gateway's rsg-dump thread")

    def signal_dumps():
        return sorted(dumps.glob("*_signal.pcap"))
    before = len(signal_dumps())
    sim = h.start("sim_stuck", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", str(RATE),
                                "--duration", "30"])
    wait_for_stats(stats, lambda s: s["link_up"], "the stream to start again")
    log = h.dir / "gateway.err"
    freeze_thread(writer)
    try:
        for _ in range(3):
            gateway.send_signal(signal.SIGUSR1)
            time.sleep(0.2)
        wait_for(lambda: "not dumped, 2 earlier dumps are still being written" in log.read_text(errors="replace"),
                 "the third SIGUSR1's dump to be refused")
        published = read_json(stats)["frames_published"]
        wait_for_stats(stats, lambda s: s["frames_published"] >= published + RATE,
                       "a second of frames published while the dump writer is stuck")
        check(len(signal_dumps()) == before, "a dump was written while its writer thread was stopped")
    finally:
        thaw_thread(writer)
    wait_for(lambda: len(signal_dumps()) == before + 2, "the two waiting dumps to be written")
    for path in signal_dumps()[before:]:
        check(len(read_capture(path)) >= RATE // 2, f"{path.name} holds less than the last second")
    sim.send_signal(signal.SIGTERM)
    h.wait("sim_stuck", sim, 30)


def body(h):
    port = free_udp_port()
    dumps = h.dir / "dumps"
    dumps.mkdir()
    metrics = free_tcp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", str(RATE),
                               "--pcap-ring", "1", "--pcap-dir", str(dumps), "--metrics", f"127.0.0.1:{metrics}",
                               "--pcap-min-interval", "0")  # every request dumps: the limits are attack_*'s
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    sent_capture = h.dir / "sent.pcap"
    status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", str(RATE), "--count",
                           str(COUNT), "--every", "1:q,time", "--every", "5:all", "--corrupt-every", "9",
                           "--pcap", str(sent_capture)])
    check(status == 0, f"rsg_sim exited {status}")

    # A loaded host can stall the simulator long enough for an earlier link-down dump: take the last.
    wait_for_stats(stats, lambda s: s["frames_received"] == COUNT and not s["link_up"], "the link to go down")
    link_down = wait_for(lambda: sorted(dumps.glob("*_link_down.pcap")), "the dump on link down")[-1]
    gateway.send_signal(signal.SIGUSR1)
    on_signal = wait_for(lambda: sorted(dumps.glob("*_signal.pcap")), "the dump on SIGUSR1")[0]
    stuck_dump_writer(h, gateway, stats, port, dumps)
    # Every dump counted by how it ended: all written (the files in the folder), one refused.
    wait_for(lambda: dump_counts(metrics) == {"written": len(list(dumps.glob("*.pcap"))), "failed": 0, "refused": 1,
                                             "throttled": 0, "no_room": 0},
             f"rsg_flight_recorder_dumps_total to count the dumps (it says {dump_counts(metrics)})")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")

    # The ring keeps at most the longest frame of a datagram (2137 bytes), as the gateway reads it.
    sent = [payload[:2 * 2137] for _, payload, _ in read_capture(sent_capture)]
    check(len(sent) == COUNT, f"the simulator's capture holds {len(sent)} datagrams")
    dumped = read_capture(link_down)
    check(read_capture(on_signal) == dumped, "the SIGUSR1 dump differs from the link-down dump (no frame came between)")
    payloads = [payload for _, payload, _ in dumped]
    check(0 < len(payloads) < COUNT, f"the dump holds {len(payloads)} of {COUNT} datagrams")
    mismatch = next((i for i, (a, b) in enumerate(zip(payloads, sent[-len(payloads):])) if a != b), None)
    check(mismatch is None, f"the dump is not the newest datagrams sent, in order: datagram {mismatch} of "
          f"{len(payloads)}: {payloads[mismatch or 0][:80]} != {sent[-len(payloads):][mismatch or 0][:80]}")
    times = [float(t) for t, _, _ in dumped]
    check(times == sorted(times) and times[-1] - times[0] <= 1.0, f"the dump spans {times[-1] - times[0]:.3f} s")
    # A second at 500 Hz, give or take what a loaded host delays: far more than the ring's minimum.
    check(len(payloads) >= RATE // 2, f"only {len(payloads)} datagrams in the last second")
    check(any(error for _, _, error in dumped), "the invalid frames are missing from the dump")


if __name__ == "__main__":
    sys.exit(main("flight_recorder", body))
