"""rsg across hosts: the simulator on `robot`, the gateway on `gw`, readers on `ops1` and `ops2`,
each a network namespace joined by a bridge (netbed.py). One scenario per run:

    test_net.py SCENARIO --bin DIR      SCENARIO: stream, views, discovery, faults, restart,
                                        multicast

Every scenario compares what readers printed with the simulator's record, line for line (as
digests: see netbed.LineDigests), and counts packets with nftables where the claim is about the
wire. Measured values are printed as MEASURED lines; pass/fail asserts exact counts, never timings,
except the 2 s resume bound of `restart`, which the issue states (with the reliability tests'
margin for a loaded 2-core machine), and the loss bound after `faults`' outage, derived from the
measured outage, the writer's history and Fast DDS's repair delays (with a stated allowance).
"""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from netbed import HOSTS, LineDigests, NetBed, discovery_server_argv, missing_runs

from harness import DEFAULT_WAIT_S, check, main, read_json, wait_for, wait_for_stats, wait_matched  # noqa: E402

SCENARIO = sys.argv.pop(1) if len(sys.argv) > 1 and not sys.argv[1].startswith("-") else "stream"
# Scenario 1's length: the issue asks for 60 s; RSG_NET_SECONDS shortens it for development.
STREAM_SECONDS = float(os.environ.get("RSG_NET_SECONDS", "60"))
RAW_PORT = 17000
DS_PORT = 11811
FRAME_BYTES = 2137
# The gateway's writer history (xml_profiles/gateway.xml, rsg_state_writer KEEP_LAST): what a
# reliable reader can still get repaired after an outage.
WRITER_HISTORY = 1000
# After an outage, the reader's first sample carries a piggybacked HEARTBEAT (the writer sends one
# with every DATA), so the reader knows at once what it misses; it answers with an ACKNACK after its
# heartbeatResponseDelay, the writer resends after its nackResponseDelay (Fast DDS defaults, which
# rsg's profiles keep: 5 ms each). At 1 kHz each of those milliseconds pushes one more sample out of
# the history before it can be resent (docs/reliability.md, "After an outage").
REPAIR_DELAY_MS = 5 + 5
# On a loaded 2-core machine the reader's and the writer's DDS threads, and the resend burst itself,
# may be descheduled for a while; a sample pushed out meanwhile is lost too. 100 ms is ten times the
# protocol's own delay (measured: 8-9 frames over the bound without it, load average 6).
LOADED_CI_ALLOWANCE_MS = 100
# Sizes of a RobotState DATA datagram (about 2.3 kB) and of anything else the gateway sends
# a reader (discovery, heartbeats: well below 1 kB).
BIG_DATAGRAM = 1800


def log(h, message):
    print(f"[{h.name}] {message}", flush=True)


class Run:
    """One scenario's bed, scratch directory and processes."""

    def __init__(self, h, bed):
        self.h, self.bed = h, bed
        self.domain = h.domain

    def start(self, host, label, argv, stdout=None):
        return self.bed.start(host, label, argv, self.h.dir, stdout=stdout)

    def gateway(self, label="gateway", *extra):
        stats = self.h.dir / f"{label}.stats.json"
        if stats.exists():
            stats.unlink()
        process = self.start("gw", label, [self.h.binary("rsg_gateway"), "--domain", self.domain, "--listen",
                                           f"{HOSTS['gw']}:{RAW_PORT}", "--stats-file", stats, *extra])
        wait_for_stats(stats, lambda s: True, f"{label} to start")
        return process, stats

    def reader(self, host, label, *extra, qos="reader_logger"):
        """An rsg_echo --json reader (by default the reliable logger) whose lines are digested as they
        arrive."""
        process = self.start(host, label, [self.h.binary("rsg_echo"), "--domain", self.domain, "--json", "--qos",
                                           qos, *extra], stdout=subprocess.PIPE)
        digests = LineDigests(stream=process.stdout)
        digests.start()
        return process, digests

    def sim(self, label, *flags):
        """Starts rsg_sim on `robot`, its record going through a FIFO into digests."""
        record, report = self.h.dir / f"{label}.record", self.h.dir / f"{label}.report.json"
        os.mkfifo(record)
        digests = LineDigests(path=record)
        digests.start()
        process = self.start("robot", label, [self.h.binary("rsg_sim"), "--to", f"{HOSTS['gw']}:{RAW_PORT}",
                                              "--record", record, "--report", report, *flags])
        return process, digests, report

    def finish_sim(self, label, process, digests, report, timeout_s):
        started = time.monotonic()
        status = self.h.wait(label, process, timeout_s)
        check(status == 0, f"{label} exited {status}")
        digests.join(10)
        return read_json(report), time.monotonic() - started


def wait_delivered(label, reader, sent, timeout_s=30):
    """Waits until `reader` printed the last frame sent (delivery is in order)."""
    wait_for(lambda: reader.digests[-1:] == sent[-1:], f"{label} to print the last frame sent", timeout_s)


def check_exactly_once(label, reader, sent):
    wait_delivered(label, reader, sent)
    got = reader.digests
    if got != sent:
        runs = missing_runs(sent, got)
        check(False, f"{label} printed {len(got)} samples for {len(sent)} frames sent"
                     + (f"; missing {runs[:5]}" if runs else "; not a subsequence of the frames sent"))


def check_gateway(stats, report):
    final = wait_for_stats(stats, lambda s: s["frames_received"] >= report["sent"], "the gateway to count every frame")
    got = {k: final[k] for k in ("frames_received", "frames_published", "lost", "duplicated", "reordered")}
    want = {"frames_received": report["sent"], "frames_published": report["sent"], "lost": 0, "duplicated": 0,
            "reordered": 0}
    check(got == want, f"gateway counters {got} != {want}")
    return final


def vm_rss_kib(pid):
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    return 0


# ----- 1. the stream across hosts ----------------------------------------------------------------------

def stream(run, h):
    count = int(STREAM_SECONDS * 1000)
    read_ops1 = run.bed.counters("ops1", {"from_gw": ("input", f"ip saddr {HOSTS['gw']} meta l4proto udp"),
                                          "fragments": ("prerouting", f"ip saddr {HOSTS['gw']} ip frag-off & 0x3fff != 0")})
    gateway, stats = run.gateway()
    readers = {host: run.reader(host, f"echo_{host}")[1] for host in ("ops1", "ops2")}
    wait_matched(h, stats, ["echo_ops1", "echo_ops2"], "rsg_echo")
    process, sent, report = run.sim("sim", "--rate", "1000", "--count", count)
    report, seconds = run.finish_sim("sim", process, sent, report, STREAM_SECONDS + 60)
    log(h, f"MEASURED rsg_sim sent {report['sent']} full frames in {seconds:.1f} s ({report['sent'] / seconds:.0f}/s)")
    check(report["sent"] == count and len(sent.digests) == count, f"the simulator sent {report['sent']} of {count}")
    for host, reader in readers.items():
        check_exactly_once(f"echo_{host}", reader, sent.digests)
        span = reader.times[-1] - reader.times[0]
        log(h, f"MEASURED {host} received {len(reader.digests)} samples in {span:.1f} s "
               f"({(len(reader.digests) - 1) / span:.0f}/s), each exactly once with the values sent")
    check_gateway(stats, report)
    got = read_ops1()
    packets, size = got["from_gw"]
    log(h, f"MEASURED ops1 got {packets} UDP datagrams, {size} bytes from gw ({got['fragments'][0]} IP fragments)")
    # Every sample crossed the wire (no shared-memory shortcut between namespaces on one machine).
    check(size >= count * FRAME_BYTES, f"ops1 received {size} bytes over UDP, fewer than {count} frames of "
                                       f"{FRAME_BYTES} bytes: samples did not cross the link")
    check(got["fragments"][0] >= count, f"ops1 saw {got['fragments'][0]} IP fragments for {count} samples of "
                                        f"more than one 1500-byte MTU")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


# ----- 2. views across hosts: filtered by the reader ----------------------------------------------------

def views(run, h):
    count = 4000
    big = f"ip saddr {HOSTS['gw']} meta l4proto udp ip length > {BIG_DATAGRAM}"
    read_ops1 = run.bed.counters("ops1", {"samples": ("input", big)})
    read_ops2 = run.bed.counters("ops2", {"samples": ("input", big)})
    gateway, stats = run.gateway()
    # Best effort, so that no repair can add a datagram: what crosses is exactly what the writer
    # sends, once. The gateway evaluates no reader's filter (docs/operating.md, "Views and content
    # filters"): the view's host receives every sample, and the reader keeps the ones with group 2.
    _, joints = run.reader("ops1", "echo_joints", "--view", "view_joints", qos="reader_realtime")
    _, everything = run.reader("ops2", "echo_all")
    wait_matched(h, stats, ["echo_joints", "echo_all"], "rsg_echo")
    time.sleep(1.0)  # discovery's last large datagrams (endpoint announcements) are not samples
    read_ops1.reset()
    read_ops2.reset()
    # Group 0 in every frame, group 2 (joints) in every fourth: 3 of 4 frames have no group 2.
    process, sent, report = run.sim("sim", "--rate", "1000", "--count", count, "--every", "1:g0", "--every", "4:g2")
    report, _ = run.finish_sim("sim", process, sent, report, 60)
    with_joints = [d for d, g in zip(sent.digests, sent.groups) if g & (1 << 2)]
    check(len(with_joints) == count // 4, f"{len(with_joints)} frames carry group 2, expected {count // 4}")
    check_exactly_once("echo_all", everything, sent.digests)
    check_gateway(stats, report)
    time.sleep(0.5)  # the last samples on their way to ops1
    check(missing_runs(with_joints, joints.digests) is not None,
          "the view_joints reader printed a frame without group 2, or out of order, or twice")
    ops1, ops2 = read_ops1()["samples"][0], read_ops2()["samples"][0]
    log(h, f"MEASURED sample datagrams: ops1 (view_joints) {ops1}, ops2 (whole topic) {ops2}, "
           f"frames {count}, with group 2 {len(with_joints)}; the view reader printed {len(joints.digests)}")
    check(ops2 >= count, f"ops2 got {ops2} sample datagrams for {count} samples")
    check(ops1 >= count, f"ops1 got {ops1} sample datagrams for {count} samples: the gateway filtered for the "
                         f"view reader (its writer must leave filtering to the readers)")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


# ----- 3. discovery without multicast ---------------------------------------------------------------------

DISCOVERY_WINDOW_S = 6.0


def discovery(run, h):
    """The same participants (gateway on gw, readers on ops1 and ops2) discover each other three
    ways; every host counts what it sends during the same window from start-up. No frames flow,
    so what is counted is discovery (and the status topic's heartbeats)."""
    results = {}
    modes = {
        "multicast (SIMPLE)": ([], False),
        "unicast peers": (["--peer", HOSTS["gw"]], False),
        "Discovery Server on gw": (["--discovery-server", f"{HOSTS['gw']}:{DS_PORT}"], True),
    }
    for index, (mode, (flags, server)) in enumerate(modes.items()):
        readers = {}
        for host in ("gw", "ops1", "ops2"):
            run.bed.nft(host, "table inet rsg_count\ndelete table inet rsg_count\n")
        read = {host: run.bed.counters(host, {"udp": ("output", "meta l4proto udp"),
                                              "multicast": ("output", "meta l4proto udp ip daddr 224.0.0.0/4")})
                for host in ("gw", "ops1", "ops2")}
        children = []
        if server:
            children.append(("ds", run.start("gw", f"ds{index}", discovery_server_argv(DS_PORT))))
        started = time.monotonic()
        gateway, stats = run.gateway(f"gateway{index}", *flags)
        children.append(("gateway", gateway))
        for host in ("ops1", "ops2"):
            process, readers[host] = run.reader(host, f"echo{index}_{host}", *flags)
            children.append((host, process))
        matched = wait_for_stats(stats, lambda s: s["state_readers"] >= 2, f"{mode}: both readers to match")
        matched_after = time.monotonic() - started
        time.sleep(max(0.0, started + DISCOVERY_WINDOW_S - time.monotonic()))
        counted = {host: reader() for host, reader in read.items()}
        packets = sum(c["udp"][0] for c in counted.values())
        size = sum(c["udp"][1] for c in counted.values())
        multicast = sum(c["multicast"][0] for c in counted.values())
        results[mode] = (packets, size, multicast, matched_after)
        log(h, f"MEASURED {mode}: {packets} UDP packets, {size} bytes sent by gw+ops1+ops2 in "
               f"{DISCOVERY_WINDOW_S:.0f} s ({multicast} multicast); readers matched after {matched_after:.1f} s "
               f"(state_readers {matched['state_readers']})")
        for label, process in reversed(children):
            process.send_signal(signal.SIGTERM)
            run.h.wait(label, process)
    for mode in ("unicast peers", "Discovery Server on gw"):
        check(results[mode][2] == 0, f"{mode}: {results[mode][2]} multicast packets were sent")
    check(results["multicast (SIMPLE)"][2] > 0, "SIMPLE discovery sent no multicast: the counters count nothing")


# ----- 4. faults between hosts ----------------------------------------------------------------------------

def faults(run, h):
    gateway, stats = run.gateway()
    _, ops1 = run.reader("ops1", "echo_ops1")
    _, ops2 = run.reader("ops2", "echo_ops2")
    wait_matched(h, stats, ["echo_ops1", "echo_ops2"], "rsg_echo")

    # a) ops1's cable out for 2 s at 1 kHz: 2000 frames while the writer keeps the last 1000.
    # Static ARP on ops1: a host that lost its carrier re-resolves its peers only at its next ARP
    # retransmission (netbed.pin_neighbours), a delay of the host's, not of DDS's, that the bound
    # below would otherwise have to include (40-81 ms measured; docs/reliability.md).
    run.bed.pin_neighbours("ops1")
    count = 6000
    process, sent, report = run.sim("sim_outage", "--rate", "1000", "--count", count)
    wait_for(lambda: len(sent.digests) >= 1500, "1.5 s of frames")
    first_of_outage = len(sent.digests)  # the record lags the wire: the outage starts at or after it
    down = time.monotonic()
    run.bed.link("ops1", up=False)
    time.sleep(2.0)
    run.bed.link("ops1", up=True)
    outage = time.monotonic() - down  # includes both commands: never shorter than the outage
    report, _ = run.finish_sim("sim_outage", process, sent, report, 60)
    check_exactly_once("echo_ops2", ops2, sent.digests)
    wait_delivered("echo_ops1", ops1, sent.digests)
    runs = missing_runs(sent.digests, ops1.digests)
    check(runs is not None, "ops1 printed samples that were not sent, or out of order, or twice")
    lost = sum(b - a + 1 for a, b in runs)
    # The bound: the frames of the outage beyond the history, plus those written while the repair
    # was on its way (1 frame per ms at 1 kHz).
    outage_frames = round(outage * 1000)
    bound = max(0, outage_frames - WRITER_HISTORY) + REPAIR_DELAY_MS + LOADED_CI_ALLOWANCE_MS
    log(h, f"MEASURED link down {outage * 1000:.0f} ms (~{outage_frames} frames): ops1 lost {lost} frames in "
           f"{len(runs)} run(s) {runs}, {lost - max(0, outage_frames - WRITER_HISTORY)} beyond the outage's "
           f"frames minus the writer's {WRITER_HISTORY}-sample history (bound {bound}: + {REPAIR_DELAY_MS} ms "
           f"repair delay + {LOADED_CI_ALLOWANCE_MS} ms loaded-machine allowance); ops2 got all {count}")
    check(lost <= bound, f"ops1 lost {lost} frames, more than the bound {bound}")
    # What is lost is the outage's oldest frames: nothing sent before it, and nothing more than the
    # bound after the first lost one (a sample pushed out while its resend was under way may leave
    # a second short run right after the first).
    check(not runs or (runs[0][0] >= first_of_outage and runs[-1][1] - runs[0][0] + 1 <= bound),
          f"ops1 lost frames {runs}: not within {bound} frames from the outage's start (frame {first_of_outage})")
    check_gateway(stats, report)

    # b) ops1 capped at 8 Mbit/s, below the stream's ~19 Mbit/s; ops2 must not notice.
    run.bed.cap_bandwidth("ops1", "8mbit")
    before, before2 = len(ops1.digests), len(ops2.digests)
    count = 5000
    process, sent, report = run.sim("sim_capped", "--rate", "1000", "--count", count, "--seed", "7")
    rss, rates, started = [], [], time.monotonic()
    while process.poll() is None:
        rss.append(vm_rss_kib(gateway.pid))
        current = read_json(stats)  # None while the gateway rewrites it
        if current:
            rates.append(current["rate_hz"])
        time.sleep(0.5)
    rates = rates[2:-2] or [0]  # the gateway's 1 s rate window while the whole window was streaming
    report, _ = run.finish_sim("sim_capped", process, sent, report, 60)
    seconds = time.monotonic() - started
    wait_delivered("echo_ops2", ops2, sent.digests)
    check(ops2.digests[before2:] == sent.digests, "with ops1 capped, ops2 did not get every frame exactly once")
    time.sleep(2.0)  # let the capped reader drain what it still can
    capped = ops1.digests[before:]
    runs = missing_runs(sent.digests, capped)
    check(runs is not None, "the capped reader printed samples that were not sent, or out of order, or twice")
    check_gateway_total(stats, 6000 + count)
    log(h, f"MEASURED tbf 8 Mbit/s on ops1: ops1 got {len(capped)} of {count} frames (lost {count - len(capped)}, "
           f"tc dropped {run.bed.tc_drops('ops1')} packets); ops2 got all {count}; gateway rate "
           f"{min(rates):.0f}..{max(rates):.0f} Hz; gateway RSS {min(rss)}..{max(rss)} KiB over {seconds:.1f} s")
    check(len(capped) < count, "the capped reader got every frame: the cap did not bite")
    half = len(rss) // 2
    check(max(rss[half:]) <= max(rss[:half]) + 16 * 1024,
          f"gateway memory grew while a reader was capped: {rss[:half]} then {rss[half:]} KiB")

    # c) random loss: nftables drops 5 % of the datagrams reaching ops2; repairs fill the gaps.
    run.bed.nft("ops2", f"table inet rsg_loss {{\n chain input {{\n  type filter hook input priority 0;\n"
                        f"  ip saddr {HOSTS['gw']} numgen random mod 100 < 5 counter drop\n }}\n}}\n")
    before2 = len(ops2.digests)
    count = 3000
    process, sent, report = run.sim("sim_lossy", "--rate", "1000", "--count", count, "--seed", "9")
    report, _ = run.finish_sim("sim_lossy", process, sent, report, 60)
    wait_delivered("echo_ops2", ops2, sent.digests)
    check(ops2.digests[before2:] == sent.digests, "with 5 % random loss, ops2 did not get every frame exactly once")
    dropped = run.bed.exec("ops2", "nft", "list", "table", "inet", "rsg_loss")
    log(h, f"MEASURED 5 % random loss into ops2 (nftables numgen): every one of {count} frames repaired; "
           f"nft: {' '.join(dropped.split('counter')[1].split()[:4])}")
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")


def check_gateway_total(stats, total):
    final = wait_for_stats(stats, lambda s: s["frames_received"] >= total, "the gateway to count every frame")
    check(final["frames_published"] == total and final["lost"] == 0,
          f"gateway published {final['frames_published']} of {total}, lost {final['lost']}")
    return final


# ----- 5. gateway restart ---------------------------------------------------------------------------------

RESUME_S = 2.0
LOADED_CI_MARGIN = 1.5


def restart(run, h):
    gateway, stats = run.gateway("gateway1")
    readers = {host: run.reader(host, f"echo_{host}")[1] for host in ("ops1", "ops2")}
    wait_matched(h, stats, ["echo_ops1", "echo_ops2"], "rsg_echo")
    process, sent, report = run.sim("sim", "--rate", "1000", "--duration", "8")
    wait_for(lambda: all(len(r.digests) > 2000 for r in readers.values()), "2 s of samples on both readers")
    check(h.stop("gateway1", gateway) == 0, "the first gateway did not exit 0 on SIGTERM")
    stopped = time.monotonic()
    gateway, stats = run.gateway("gateway2")
    report, _ = run.finish_sim("sim", process, sent, report, 30)
    position = {digest: index for index, digest in enumerate(sent.digests)}
    for host, reader in readers.items():
        wait_delivered(f"echo_{host}", reader, sent.digests)
        check(missing_runs(sent.digests, reader.digests) is not None,
              f"{host} printed samples that were not sent, or out of order, or twice")
        # The first sample after the frames no gateway was there to publish: the new gateway's first.
        indices = [position[digest] for digest in reader.digests]
        gaps = [j for j in range(1, len(indices)) if indices[j] != indices[j - 1] + 1]
        check(len(gaps) == 1, f"{host}: {len(gaps)} gaps in the stream, expected the restart's one")
        resumed = reader.times[gaps[0]] - stopped
        log(h, f"MEASURED {host} resumed {resumed * 1000:.0f} ms after the first gateway exited "
               f"({indices[gaps[0]] - indices[gaps[0] - 1] - 1} frames unpublished meanwhile; requirement "
               f"{RESUME_S * 1000:.0f} ms)")
        check(resumed <= RESUME_S * LOADED_CI_MARGIN, f"{host} resumed after {resumed:.2f} s")
    check(h.stop("gateway2", gateway) == 0, "the second gateway did not exit 0 on SIGTERM")


# ----- 6. multicast delivery ------------------------------------------------------------------------------

PROFILES_DIR = Path(__file__).resolve().parents[2] / "xml_profiles"
# rsg_participant_multicast's group (xml_profiles/rsg.xml).
MULTICAST_GROUP = "239.255.100.1"
MULTICAST_FRAMES = 4000
# Two readers on each consumer host.
READER_HOSTS = ("ops1", "ops1", "ops2", "ops2")
# A gateway participant whose UDP transport only uses gw's plant interface (docs/scaling.md): Fast DDS
# 2.9 then opens no loopback output socket, which otherwise sends every multicast datagram once more.
GATEWAY_ON_ETH0 = f"""<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <profiles>
    <transport_descriptors>
      <transport_descriptor>
        <transport_id>gw_eth0</transport_id>
        <type>UDPv4</type>
        <interfaceWhiteList><address>{HOSTS['gw']}</address></interfaceWhiteList>
      </transport_descriptor>
    </transport_descriptors>
    <participant profile_name="gw_eth0">
      <rtps>
        <userTransports><transport_id>gw_eth0</transport_id></userTransports>
        <useBuiltinTransports>false</useBuiltinTransports>
      </rtps>
    </participant>
  </profiles>
</dds>
"""


def multicast(run, h):
    """Four remote reliable readers (two on ops1, two on ops2) of one gateway, three times: with rsg's
    default participant (unicast), with rsg_participant_multicast, and the latter again with a gateway
    whose transport is limited to gw's interface. Each time every reader prints every frame exactly
    once, and nftables on gw counts the sample datagrams it sends (one datagram per copy: the output
    hook sees them before IP fragmentation): about four per sample out of eth0 with unicast, about one
    with multicast, plus one to loopback unless the gateway's transport leaves loopback out."""
    profiles = h.dir / "profiles"
    profiles.mkdir()
    for source in PROFILES_DIR.glob("*.xml"):
        (profiles / source.name).symlink_to(source)
    (profiles / "gw_eth0.xml").write_text(GATEWAY_ON_ETH0)
    readers_ip = "{ " + ", ".join(HOSTS[host] for host in ("ops1", "ops2")) + " }"
    big = f"meta l4proto udp ip length > {BIG_DATAGRAM}"
    read_gw = run.bed.counters("gw", {"unicast": ("output", f"oifname eth0 ip daddr {readers_ip} {big}"),
                                      "multicast": ("output", f"oifname eth0 ip daddr {MULTICAST_GROUP} {big}"),
                                      "other_if": ("output", f"oifname != eth0 ip daddr {MULTICAST_GROUP} {big}")})
    read_ops = {host: run.bed.counters(host, {"multicast": ("input", f"ip daddr {MULTICAST_GROUP} {big}")})
                for host in ("ops1", "ops2")}
    multicast_readers = ["--participant-profile", "rsg_participant_multicast"]
    modes = {"unicast": ([], []), "multicast": ([], multicast_readers),
             "multicast_eth0": (["--profiles", profiles, "--participant-profile", "gw_eth0"], multicast_readers)}
    copies, looped = {}, {}
    for seed, (mode, (gateway_flags, reader_flags)) in enumerate(modes.items()):
        gateway, stats = run.gateway(f"gateway_{mode}", *gateway_flags)
        readers = [run.reader(host, f"echo_{mode}{index}", *reader_flags) for index, host in enumerate(READER_HOSTS)]
        wait_matched(h, stats, [f"echo_{mode}{index}" for index in range(len(readers))], "rsg_echo")
        time.sleep(1.0)  # discovery's last large datagrams (endpoint announcements) are not samples
        read_gw.reset()
        for read in read_ops.values():
            read.reset()
        process, sent, report = run.sim(f"sim_{mode}", "--rate", "1000", "--count", MULTICAST_FRAMES, "--seed",
                                        seed + 3)
        report, _ = run.finish_sim(f"sim_{mode}", process, sent, report, 60)
        for index, (_, reader) in enumerate(readers):
            check_exactly_once(f"echo_{mode}{index}", reader, sent.digests)
        check_gateway(stats, report)
        time.sleep(0.5)  # heartbeats and acknowledgements of the last samples
        counted = read_gw()
        received = {host: read()["multicast"][0] for host, read in read_ops.items()}
        unicast, group = counted["unicast"][0], counted["multicast"][0]
        copies[mode] = (unicast + group) / MULTICAST_FRAMES
        looped[mode] = counted["other_if"][0] / MULTICAST_FRAMES
        log(h, f"MEASURED {mode}: {len(readers)} readers each printed all {MULTICAST_FRAMES} frames once; gw sent "
               f"{unicast} unicast + {group} multicast sample datagrams out of eth0 = {copies[mode]:.2f} per sample, "
               f"and {counted['other_if'][0]} to the group on loopback; multicast sample datagrams received: "
               f"{received}")
        if mode != "unicast":
            for host, count in received.items():
                check(count >= MULTICAST_FRAMES, f"{mode}: {host} received {count} multicast sample datagrams for "
                                                 f"{MULTICAST_FRAMES} samples: the samples did not come by multicast")
        for index, (reader, _) in enumerate(readers):
            check(h.stop(f"echo_{mode}{index}", reader) == 0, f"echo_{mode}{index} did not exit 0 on SIGTERM")
        check(h.stop(f"gateway_{mode}", gateway) == 0, f"gateway_{mode} did not exit 0 on SIGTERM")
    check(copies["unicast"] >= 3.5, f"unicast: {copies['unicast']:.2f} copies per sample for 4 remote readers "
                                    f"(expected about 4): the counters do not count the samples")
    for mode in ("multicast", "multicast_eth0"):
        check(copies[mode] <= 1.3, f"{mode}: {copies[mode]:.2f} copies per sample out of eth0 for 4 readers sharing "
                                   f"a group (expected about 1)")
    check(looped["multicast_eth0"] == 0, f"the gateway limited to eth0 still sent {looped['multicast_eth0']:.2f} "
                                         f"copies per sample to loopback")


SCENARIOS = {"stream": stream, "views": views, "discovery": discovery, "faults": faults, "restart": restart,
             "multicast": multicast}


def body(h):
    with NetBed() as bed:
        h.children = bed.children
        SCENARIOS[SCENARIO](Run(h, bed), h)


if __name__ == "__main__":
    sys.exit(main(f"net_{SCENARIO}", body))
