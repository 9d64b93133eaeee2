"""Hostile datagrams: zero-length and oversized ones (2138 .. 65507 bytes), first paced and then as a
5-second flood from rsg_flood as fast as it can send (over 100,000 a second on an idle 2-core host;
the rate is logged, not asserted: it measures the host, and the counters below hold at any rate).

Pins that the gateway
  * counts each of them in its spec category (zero-length: truncated; larger than the largest frame
    with a header claiming the largest data section: length_mismatch), exactly when paced, and for
    every datagram it received during the flood (the rest the kernel dropped at its full socket
    buffer, which /proc/net/udp counts);
  * publishes none of them, stays up, and keeps its memory bounded (VmRSS before and after);
  * does not stall afterwards: a normal stream sent right after the flood reaches a reliable reader
    frame for frame, with no loss counted.
"""

import sys

from reliability import (check, check_delivered_exactly_once, log, main, read_json, run_sim, start_gateway,
                         start_logger, stop_child, udp_socket_drops, vm_kib, wait_for, wait_for_readers,
                         wait_for_stats)
from harness import wait_reader_matched  # noqa: E402

RATE_HZ = 1000
OVERSIZED = (2138, 9000, 30000, 65507)
PACED = ["--sizes", ",".join(map(str, (0, *OVERSIZED))), "--count", "2000", "--rate", "2000"]
# Mostly zero-length (cheap enough for > 100k/s on an idle 2-core host), some oversized, one in 32
# the largest.
FLOOD_SIZES = [0] * 24 + [2138] * 4 + [9000, 2138, 30000, 65507]
FLOOD = ["--sizes", ",".join(map(str, FLOOD_SIZES)), "--duration", "5"]
# The gateway allocates its receive buffer at start-up and nothing per datagram; what may grow is
# DDS and allocator bookkeeping. 8 MiB is far below what keeping even 1 % of the flood would cost.
RSS_GROWTH_LIMIT_KIB = 8 * 1024


def flood(h, port, label, args):
    """Runs rsg_flood; returns its report."""
    report = h.dir / f"{label}.json"
    status = h.run(label, [h.binary("rsg_flood"), "--to", f"127.0.0.1:{port}", *args, "--report", str(report)])
    check(status == 0, f"{label} exited {status}")
    return read_json(report)


def invalid_by_size(by_size):
    """The counters that datagrams of these sizes must raise, per docs/protocol.md's validation order."""
    truncated = sum(n for size, n in by_size.items() if int(size) < 14)
    return {"truncated": truncated, "length_mismatch": sum(by_size.values()) - truncated}


def gateway_counts(stats):
    return {"received": stats["frames_received"], "published": stats["frames_published"],
            "truncated": stats["invalid"]["truncated"], "length_mismatch": stats["invalid"]["length_mismatch"],
            "other_invalid": sum(stats["invalid"].values()) - stats["invalid"]["truncated"]
            - stats["invalid"]["length_mismatch"]}


def after(stats, before_counts, received_at_least):
    """The counters accumulated since `before_counts`, once the gateway has received enough."""
    final = wait_for_stats(stats, lambda s: s["frames_received"] >= received_at_least,
                           f"the gateway to receive {received_at_least} datagrams")
    return {key: value - before_counts[key] for key, value in gateway_counts(final).items()}


def body(h):
    gateway, stats, port = start_gateway(h, RATE_HZ)
    logger = start_logger(h, "logger", timeout_s=80)
    wait_for_readers(stats, 1)
    wait_reader_matched(h, "logger", "rsg_echo")

    # Paced: every datagram reaches the gateway, so every counter is exact.
    start = gateway_counts(read_json(stats))
    paced = flood(h, port, "paced", PACED)
    delta = after(stats, start, start["received"] + paced["sent"])
    expected = {"received": paced["sent"], "published": 0, **invalid_by_size(paced["by_size"]), "other_invalid": 0}
    check(delta == expected, f"paced hostile datagrams: gateway counted {delta}, expected {expected}")

    # Flood.
    rss_before = vm_kib(gateway.pid, "VmRSS")
    drops_before = udp_socket_drops(port)
    start = gateway_counts(read_json(stats))
    flooded = flood(h, port, "flood", FLOOD)
    rate = flooded["sent"] / flooded["seconds"]
    log(h, f"MEASURED flood: {flooded['sent']} datagrams in {flooded['seconds']:.2f} s = {rate:.0f}/s")
    check(gateway.poll() is None, f"the gateway exited ({gateway.returncode}) during the flood")
    # Every datagram sent either reached the gateway or was dropped by the kernel at the gateway's full
    # socket buffer (nothing is lost elsewhere on loopback); wait until the gateway drained the rest.
    def drained():
        delta = after(stats, start, 0)
        dropped = udp_socket_drops(port) - drops_before
        return (delta, dropped) if delta["received"] + dropped == flooded["sent"] else None
    delta, dropped = wait_for(drained, "the gateway to receive every flood datagram the kernel did not drop")
    rss_after, rss_peak = vm_kib(gateway.pid, "VmRSS"), vm_kib(gateway.pid, "VmHWM")
    log(h, f"MEASURED flood: gateway received {delta['received']}, kernel dropped {dropped} at the full socket buffer")
    log(h, f"MEASURED gateway VmRSS {rss_before} KiB before the flood, {rss_after} KiB after "
           f"(peak {rss_peak} KiB)")

    check(delta["published"] == 0 and delta["other_invalid"] == 0, f"flood: the gateway counted {delta}")
    check(delta["received"] == delta["truncated"] + delta["length_mismatch"],
          f"flood: not every datagram received was counted invalid: {delta}")
    sent = invalid_by_size(flooded["by_size"])
    check(delta["truncated"] <= sent["truncated"] and delta["length_mismatch"] <= sent["length_mismatch"],
          f"flood: the gateway counted more than was sent: {delta} vs {sent}")
    check(rss_after - rss_before <= RSS_GROWTH_LIMIT_KIB,
          f"the gateway's VmRSS grew by {rss_after - rss_before} KiB during the flood")

    # Right after: a normal stream, frame for frame.
    before = read_json(stats)
    report, record, _ = run_sim(h, port, RATE_HZ, 2000, "--fields", "q,time")
    check_delivered_exactly_once(h, "logger", record)
    final = wait_for_stats(stats, lambda s: s["frames_received"] >= before["frames_received"] + report["sent"],
                           "the gateway to count the stream after the flood")
    check(final["frames_published"] - before["frames_published"] == report["valid"]
          and final["lost"] == before["lost"],
          f"the stream after the flood: published {final['frames_published'] - before['frames_published']} of "
          f"{report['valid']}, lost {final['lost'] - before['lost']}")

    check(stop_child(h, "logger", logger) == 0, "rsg_echo did not exit 0")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


if __name__ == "__main__":
    sys.exit(main("hostile_datagrams", body))
