"""Where the recording tests replay raw frames to: a second gateway publishing on its own topics
("replayed", "replayed_status") and an rsg_echo --json matched to it, waiting for `count` samples."""

from harness import free_udp_port, wait_for_stats


def second_gateway_with_echo(h, count, echo_label):
    """(the second gateway's process, the UDP port it listens on, the rsg_echo process)."""
    port = free_udp_port()
    gateway, stats = h.gateway("gateway2", "--listen", f"127.0.0.1:{port}", "--topic", "replayed",
                               "--status-topic", "replayed_status", "--expected-rate", "1000")
    echo = h.start(echo_label, [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "replayed", "--json",
                                "--count", str(count), "--timeout", "30"])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1, "rsg_echo to match the second gateway")
    return gateway, port, echo
