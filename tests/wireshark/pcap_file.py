"""Writes classic pcap files of UDP/IPv4 datagrams (LINKTYPE_IPV4), standard library only.

An encoder independent of rsg's own pcap writer, so the dissector tests build their captures
without trusting the code under test.
"""

import struct

LINKTYPE_IPV4 = 228


def ipv4_udp(payload, source_port, destination_port, source="127.0.0.1", destination="127.0.0.1"):
    """One IPv4 packet carrying one UDP datagram (UDP checksum 0: "not computed", valid for IPv4)."""
    udp = struct.pack("!HHHH", source_port, destination_port, 8 + len(payload), 0) + payload
    header = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(udp), 0, 0x4000, 64, 17, 0,
                         bytes(map(int, source.split("."))), bytes(map(int, destination.split("."))))
    total = sum(struct.unpack("!10H", header))
    while total > 0xFFFF:
        total = (total & 0xFFFF) + (total >> 16)
    return header[:10] + struct.pack("!H", ~total & 0xFFFF) + header[12:] + udp


def write(path, datagrams):
    """datagrams: (payload, source_port, destination_port) tuples, written 1 ms apart."""
    with open(path, "wb") as out:
        out.write(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, LINKTYPE_IPV4))
        for number, (payload, source_port, destination_port) in enumerate(datagrams):
            packet = ipv4_udp(payload, source_port, destination_port)
            out.write(struct.pack("<IIII", 1000 + number // 1000, (number % 1000) * 1000, len(packet), len(packet)))
            out.write(packet)
