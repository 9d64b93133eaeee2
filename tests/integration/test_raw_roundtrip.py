"""raw -> DDS -> raw through two gateways (ingress on one, egress on the other): every frame
comes out byte-identical. A tap between the sim and the first gateway records the bytes sent.
A header-only frame (no field selected, 14 bytes) is byte for byte a selection request, so egress
refuses it and counts it (egress_request_like) instead of sending the robot a request."""

import sys

from harness import UdpRelay, check, main, wait_for, wait_for_stats, free_udp_port

COUNT = 600
RATE = "300"


def body(h):
    ingress_port, tap_port, sink_port = free_udp_port(), free_udp_port(), free_udp_port()
    ingress, ingress_stats = h.gateway("ingress", "--listen", f"127.0.0.1:{ingress_port}", "--topic", "arm",
                                       "--expected-rate", RATE)
    egress, egress_stats = h.gateway("egress", "--egress-topic", "arm", "--send-to", f"127.0.0.1:{sink_port}",
                                     "--status-topic", "egress_status")
    sink = UdpRelay(sink_port)
    tap = UdpRelay(tap_port, forward_to=("127.0.0.1", ingress_port))
    sink.start()
    tap.start()
    try:
        wait_for_stats(ingress_stats, lambda s: s["state_readers"] >= 1, "the egress reader to match the ingress writer")
        wait_for_stats(egress_stats, lambda s: s["egress_writers"] >= 1, "the egress reader to see the ingress writer")

        # All fields (2137-byte frames), joints only, and a header-only frame now and then.
        status = h.run("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{tap_port}", "--rate", RATE,
                               "--count", str(COUNT), "--every", "2:q,dq,tau_J,time", "--every", "5:all"])
        check(status == 0, f"rsg_sim exited {status}")
        # Frames 0, 2, 4, 5, 6, 8, 10 ... carry fields; the others are header-only.
        states = [i for i in range(COUNT) if i % 2 == 0 or i % 5 == 0]
        wait_for(lambda: len(sink.datagrams) >= len(states),
                 f"{len(states)} frames at the sink (have {len(sink.datagrams)})")
        final = wait_for_stats(egress_stats, lambda s: s["egress_samples"] >= COUNT, "egress to take every sample")
    finally:
        tap.stop()
        sink.stop()

    check(len(tap.datagrams) == COUNT, f"the tap saw {len(tap.datagrams)} datagrams, not {COUNT}")
    check(len(sink.datagrams) == len(states), f"the sink got {len(sink.datagrams)} frames for {len(states)} states")
    check(final["egress_request_like"] == COUNT - len(states) and final["egress_frames_sent"] == len(states),
          f"egress counters: {final}")
    check(all(len(datagram) > 14 for datagram in sink.datagrams), "egress sent a header-only frame")
    expected = [tap.datagrams[i] for i in states]
    for index, (sent, received) in enumerate(zip(expected, sink.datagrams)):
        check(sent == received, f"frame {index} differs: sent {sent.hex()[:80]}..., got {received.hex()[:80]}...")
    check(h.stop("ingress", ingress) == 0 and h.stop("egress", egress) == 0, "a gateway did not exit 0")


if __name__ == "__main__":
    sys.exit(main("raw_roundtrip", body))
