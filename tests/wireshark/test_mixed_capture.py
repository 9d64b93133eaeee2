#!/usr/bin/env python3
"""A real capture of mixed traffic: SEND_BUF frames on three non-default UDP ports (one of them into a
running gateway) and the RTPS traffic of that gateway and an rsg_echo reader, taken from the
loopback interface by Debian's dumpcap. Read back by tshark with rsg's dissector, the heuristic
claims exactly the SEND_BUF datagrams, and tshark's RTPS dissector keeps the DDS traffic.

    tests/wireshark/test_mixed_capture.py --bin build/bin
"""

import signal
import subprocess
import sys
import time

from harness import TestFailure, check, main, wait_for, wait_for_stats, wait_reader_matched, free_udp_port  # noqa: E402

import tshark_run  # noqa: E402

COUNT = 100


def body(h):
    for tool in ("dumpcap", "tshark"):
        check(subprocess.run(["which", tool], capture_output=True).returncode == 0,
              f"{tool} is not installed (docker/packages.txt lists tshark; run `make deps`)")
    # Ports Wireshark decodes by number (5868 is DTLS's) go to that dissector before any heuristic
    # runs (docs/raw-leg.md), and 17000 is the dissector's own: the robots here use none of them.
    decoded = tshark_run.ports_decoded_by_number()
    ports = []
    while len(ports) < 3:
        port = free_udp_port()
        if port != 17000 and port not in decoded:
            ports.append(port)
    rtps_first = 7400 + 250 * h.domain  # the RTPS ports of this test's DDS domain
    capture = h.dir / "mixed.pcapng"
    bpf = "udp and (" + " or ".join(f"dst port {p}" for p in ports) + f" or portrange {rtps_first}-{rtps_first + 249})"
    dumpcap = h.start("dumpcap", ["dumpcap", "-q", "-i", "lo", "-f", bpf, "-w", str(capture)])
    wait_for(lambda: capture.exists() and capture.stat().st_size > 0, "dumpcap to start capturing")

    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{ports[0]}", "--expected-rate", "500")
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    echo = h.start("echo", [h.binary("rsg_echo"), "--domain", str(h.domain), "--json", "--count", str(COUNT),
                            "--timeout", "30"])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, "rsg_echo to match the gateway")
    wait_reader_matched(h, "echo", "rsg_echo")
    for index, port in enumerate(ports):
        status = h.run(f"sim{index}", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "500",
                                       "--count", str(COUNT), "--every", "1:q,time", "--every", "7:all"])
        check(status == 0, f"rsg_sim to port {port} exited {status}")
    check(h.wait("echo", echo, 30) == 0, "rsg_echo did not receive the gateway's samples")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0")
    time.sleep(0.5)  # let dumpcap take the last datagrams off the interface
    dumpcap.send_signal(signal.SIGINT)
    check(h.wait("dumpcap", dumpcap, 10) == 0, "dumpcap did not finish the capture")

    rows = tshark_run.fields(capture, ["frame.number", "udp.dstport", "frame.protocols", "sendbuf.packet_number"])
    sendbuf_ports = {str(p) for p in ports}
    expected = [r["frame.number"][0] for r in rows if r["udp.dstport"] and r["udp.dstport"][0] in sendbuf_ports]
    claimed = [r["frame.number"][0] for r in rows if r["sendbuf.packet_number"]]
    rtps = [r["frame.number"][0] for r in rows if "rtps" in r["frame.protocols"][0].split(":")]
    check(len(expected) == 3 * COUNT, f"the capture holds {len(expected)} SEND_BUF datagrams, not {3 * COUNT}")
    check(claimed == expected, f"the heuristic claimed {len(claimed)} datagrams; "
          f"{len(set(claimed) - set(expected))} are not SEND_BUF, {len(set(expected) - set(claimed))} SEND_BUF missed")
    check(len(rtps) > 0, "the capture holds no RTPS datagram: the test saw no DDS traffic")
    check(not set(rtps) & set(claimed), "datagrams were claimed by both RTPS and SEND_BUF")
    print(f"[mixed_capture] {len(rows)} datagrams: {len(claimed)} SEND_BUF on ports {ports}, {len(rtps)} RTPS")


if __name__ == "__main__":
    sys.exit(main("mixed_capture", body))
