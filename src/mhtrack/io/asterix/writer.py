"""Data blocks written as a raw ASTERIX stream (``.ast``: blocks back to back) or a pcap
of UDP datagrams (``.pcap``: libpcap 2.4, microsecond times, Ethernet/IPv4/UDP, one data
block per datagram), atomically through :mod:`mhtrack.io.atomic`.

In the pcap each radar sends from 10.0.S.I (its SAC and SIC) port 5000 to the multicast
group 232.1.1.1 port 8600; the packet time is the message's time (seconds of the plots
file, as POSIX seconds: a file starting at 0 s starts on 1970-01-01).
"""

from __future__ import annotations

import struct
from collections.abc import Iterable
from pathlib import Path

from mhtrack.io.atomic import atomic_write

DEST_IP, DEST_PORT, SRC_PORT = bytes([232, 1, 1, 1]), 8600, 5000
#: Ethernet multicast MAC of 232.1.1.1 (01:00:5e + the low 23 bits of the group).
DEST_MAC = bytes([0x01, 0x00, 0x5E, 0x01, 0x01, 0x01])


def _checksum(header: bytes) -> int:
    """The IPv4 header checksum (RFC 791: ones' complement of the ones' complement sum)."""
    s = sum(struct.unpack(f"!{len(header) // 2}H", header))
    while s >> 16:
        s = (s & 0xFFFF) + (s >> 16)
    return ~s & 0xFFFF


def datagram(block: bytes, sensor: int, ident: int) -> bytes:
    """An Ethernet/IPv4/UDP frame carrying ``block`` from radar ``sensor``."""
    src_ip = bytes([10, 0, (sensor >> 8) & 0xFF, sensor & 0xFF])
    udp = struct.pack("!HHHH", SRC_PORT, DEST_PORT, 8 + len(block), 0) + block
    ip = struct.pack("!BBHHHBBH4s4s", 0x45, 0, 20 + len(udp), ident & 0xFFFF, 0x4000,
                     32, 17, 0, src_ip, DEST_IP)
    ip = ip[:10] + struct.pack("!H", _checksum(ip)) + ip[12:]
    src_mac = bytes([0x02, 0, 0, 0, (sensor >> 8) & 0xFF, sensor & 0xFF])
    return DEST_MAC + src_mac + b"\x08\x00" + ip + udp


def write_blocks(path: str | Path, blocks: Iterable[tuple[float, int, bytes]]) -> int:
    """Write ``(time, sensor, block)`` to ``path`` (``.pcap`` or raw for any other
    suffix); returns the number of blocks."""
    parts: list[bytes] = []
    pcap = Path(path).suffix.lower() == ".pcap"
    if pcap:
        parts.append(struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1))
    n = 0
    for n, (time, sensor, block) in enumerate(blocks, start=1):
        if pcap:
            frame = datagram(block, sensor, n)
            usec = round(max(time, 0.0) * 1e6)
            parts.append(struct.pack("<IIII", usec // 1_000_000, usec % 1_000_000,
                                     len(frame), len(frame)))
            parts.append(frame)
        else:
            parts.append(block)
    atomic_write(path, b"".join(parts))
    return n
