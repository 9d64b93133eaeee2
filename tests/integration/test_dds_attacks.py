"""No packet and no DDS peer can take the gateway down (docs/fastdds-versions.md, "What no packet can do").

Against a gateway fed at 1 kHz with a reader attached, on loopback (tests/support/dds_attacks.py):
  1. the 84-byte datagram with a misplaced eProsima statistics submessage that aborts every Fast DDS
     2.9.1 / 3.1.2 process Debian builds, sent to every port a participant of the domain listens on;
  2. two readers whose participant announces a unicast and a multicast user locator (a legal
     profile), on which Fast DDS 2.9.1 / 3.1.2 abort in OutputTrafficManager::set_statistics_message_data;
  3. 3,000 random RTPS datagrams with statistics submessages anywhere;
  4. 2,000 announcements of made-up participants from one socket, each with the longest lease:
     Fast DDS's default keeps every one, never freed, and the cap on remote participants
     (kMaxRemoteParticipants, 256) alone would then refuse every later one; the gateway's
     admission (src/dds/internal/spdp_admission.hpp) keeps at most 4 of them on probation, so a
     participant announced after them is answered, the readers matched before keep their samples,
     and its memory stays bounded;
  5. a sustained flood (300 made-up participants re-announced every 2 s, as an attacker would keep
     it up): a reader started during it is matched and served, and the flood is counted.
After each the gateway must still run and publish, every reader get its samples, and
rsg_dds_guard_total on /metrics say what the guard did."""

import sys
import threading
import time
from pathlib import Path

from harness import check, main, read_json, wait_for, wait_for_stats, free_udp_port
from metrics_support import free_tcp_port, http_get, parse_samples, value_of
from dds_attacks import (TWO_LOCATORS_PROFILE, TWO_LOCATORS_XML, answers_new_participant, guard_counts,
                         one_datagram, random_datagrams, send_to_domain, spoof_participants, spoof_participants_for,
                         udp_ports_of)

# Made-up participants announced to the gateway's own ports, 8 times the 256 it keeps; what they may
# add to its resident memory: the 256, the datagrams' transient buffers and the allocator's slack.
SPOOFED = 2000
SPOOF_RSS_GROWTH_LIMIT_KB = 8 * 1024
# The sustained flood: as many made-up participants as the issue's attacker kept up (~77 kB/s).
FLOOD_PARTICIPANTS, FLOOD_PERIOD_S, FLOOD_SECONDS = 300, 2.0, 14.0

PROFILES = Path(__file__).resolve().parents[2] / "xml_profiles"


def scrape_guard(metrics_port):
    reply = http_get(metrics_port, "/metrics")
    check(reply is not None and reply[0] == 200, f"/metrics did not answer: {reply}")
    return guard_counts(parse_samples(reply[1]), value_of)


def needs_send_channel_guard(metrics_port):
    """Whether the gateway's Fast DDS forgets the send channel (before 2.14.5, 3.x before 3.1.3):
    only there does the guard have one to open."""
    reply = http_get(metrics_port, "/metrics")
    check(reply is not None and reply[0] == 200, f"/metrics did not answer: {reply}")
    labels = [l for n, l, _ in parse_samples(reply[1]) if n == "rsg_build_info"]
    check(len(labels) == 1 and "fastdds_version" in labels[0], f"rsg_build_info: {labels}")
    version = tuple(int(part) for part in labels[0]["fastdds_version"].split(".")[:3])
    return version < (2, 14, 5) or (3, 0, 0) <= version < (3, 1, 3)


def resident_kb(pid):
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise AssertionError(f"no VmRSS for {pid}")


def check_alive_and_publishing(gateway, stats, what):
    check(gateway.poll() is None, f"the gateway died after {what} (exit {gateway.returncode})")
    before = read_json(stats)["frames_published"]
    wait_for_stats(stats, lambda s: s["frames_published"] >= before + 500, f"the gateway to publish after {what}")


def body(h):
    port, metrics_port = free_udp_port(), free_tcp_port()
    gateway, stats = h.gateway("gateway", "--listen", f"127.0.0.1:{port}", "--expected-rate", "1000",
                               "--metrics", f"127.0.0.1:{metrics_port}")
    wait_for_stats(stats, lambda s: True, "the gateway to start")
    h.start("sim", [h.binary("rsg_sim"), "--to", f"127.0.0.1:{port}", "--rate", "1000", "--duration", "90"])
    plain = h.start("plain", [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "robot_state",
                              "--json", "--timeout", "95"])
    wait_for_stats(stats, lambda s: s["state_readers"] >= 1 and s["frames_published"] > 500,
                   "a reader to match and frames to be published")

    send_to_domain(h.domain, [one_datagram()] * 3)
    time.sleep(0.5)
    check_alive_and_publishing(gateway, stats, "the 84-byte statistics datagram")
    wait_for(lambda: scrape_guard(metrics_port)["statistics_misplaced"] >= 1,
             "rsg_dds_guard_total to count the misplaced statistics submessage")

    profile = h.dir / "two_locators.xml"
    profile.write_text(TWO_LOCATORS_XML)
    readers = []
    for i in range(3):  # side by side: the second one to match is the one Fast DDS sends to unopened
        readers.append(h.start(f"two_locators{i}", [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic",
                                                    "robot_state", "--json", "--count", "1000", "--timeout", "30",
                                                    "--profiles", str(PROFILES), "--profiles", str(profile),
                                                    "--participant-profile", TWO_LOCATORS_PROFILE]))
        time.sleep(0.7)
    for i, reader in enumerate(readers):
        check(h.wait(f"two_locators{i}", reader, 40) == 0, f"reader {i} on two locators did not get 1000 samples")
    check_alive_and_publishing(gateway, stats, "two readers on a unicast and a multicast locator")
    if needs_send_channel_guard(metrics_port):
        wait_for(lambda: scrape_guard(metrics_port)["send_channel_opened"] >= 1,
                 "rsg_dds_guard_total to count the send channel the guard opened")

    send_to_domain(h.domain, random_datagrams(3000))
    time.sleep(0.5)
    check_alive_and_publishing(gateway, stats, "3,000 random RTPS datagrams")
    print(f"[dds_attacks] guard: {scrape_guard(metrics_port)}", flush=True)

    gateway_ports = udp_ports_of(gateway.pid)
    check(answers_new_participant(h.domain, free_udp_port(), gateway_ports),
          "the gateway did not answer a new participant before the spoofing")
    before_kb = resident_kb(gateway.pid)
    spoof_participants(h.domain, SPOOFED, gateway_ports)
    time.sleep(1.0)
    check(answers_new_participant(h.domain, free_udp_port(), gateway_ports),
          f"the gateway no longer answers a new participant after {SPOOFED} spoofed ones")
    refused = scrape_guard(metrics_port)["announcement_refused"]
    check(refused >= SPOOFED - 10, f"rsg_dds_guard_total{{action=\"announcement_refused\"}} is {refused}, "
          f"not about {SPOOFED}: the made-up participants were not refused")
    check_alive_and_publishing(gateway, stats, f"{SPOOFED} spoofed participant announcements")
    growth_kb = resident_kb(gateway.pid) - before_kb
    print(f"[dds_attacks] {SPOOFED} spoofed participants: resident memory {before_kb} kB + {growth_kb} kB", flush=True)
    check(growth_kb < SPOOF_RSS_GROWTH_LIMIT_KB,
          f"{SPOOFED} spoofed participants grew the gateway by {growth_kb} kB (limit {SPOOF_RSS_GROWTH_LIMIT_KB} kB)")

    flood = threading.Thread(target=spoof_participants_for, name="flood",
                             args=(h.domain, FLOOD_PARTICIPANTS, gateway_ports, FLOOD_SECONDS, FLOOD_PERIOD_S))
    flood.start()
    try:
        time.sleep(2 * FLOOD_PERIOD_S)
        late = h.start("late", [h.binary("rsg_echo"), "--domain", str(h.domain), "--topic", "robot_state", "--json",
                                "--count", "500", "--timeout", "20"])
        check(h.wait("late", late, 30) == 0, "a reader started during a sustained discovery flood got no samples")
    finally:
        flood.join()
    check_alive_and_publishing(gateway, stats, "a sustained discovery flood")
    print(f"[dds_attacks] after the sustained flood: {scrape_guard(metrics_port)}", flush=True)

    check(plain.poll() is None, f"the plain reader stopped (exit {plain.returncode})")
    lines = h.output("plain").read_text().count("\n")
    check(lines > 1000, f"the plain reader printed only {lines} samples")
    stop_start = time.monotonic()
    check(h.stop("gateway", gateway) == 0, "the gateway did not exit 0 on SIGTERM")
    print(f"[dds_attacks] the gateway exited {time.monotonic() - stop_start:.2f} s after SIGTERM", flush=True)


if __name__ == "__main__":
    sys.exit(main("dds_attacks", body))
