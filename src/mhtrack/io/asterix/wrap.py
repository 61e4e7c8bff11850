"""Data blocks wrapped in the framings that :mod:`mhtrack.io.asterix.framings` reads: the
recorder formats (ORADIS, GPS, Final), captures (pcap, pcapng) and link layers (VLAN tags,
Linux cooked v1/v2, IEEE 802.3 + LLC), to the layouts documented there. Used to write test
recordings and recordings for other tools; each function returns the octets.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence

from mhtrack.io.asterix.framings import FINAL_PAD, GPS_HEADER
from mhtrack.io.asterix.writer import datagram


def tod_raw(time: float, lsb: float, bits: int) -> int:
    """A time's seconds of the day in units of ``lsb``, on ``bits`` bits."""
    return round((time % 86400.0) / lsb) % (1 << bits)


def oradis(blocks: Sequence[bytes], times: Sequence[float]) -> bytes:
    """ORADIS records (one per block; the 4-octet time in ms of the day)."""
    return b"".join(struct.pack("!HI", 6 + len(b), tod_raw(t, 1e-3, 32)) + b
                    for b, t in zip(blocks, times, strict=True))


def gps(blocks: Sequence[bytes], times: Sequence[float], header: bytes = b"") -> bytes:
    """A GPS recording: a 2 200-octet header (``header`` padded with zeros), each block
    followed by 10 octets with the time of day in 1/128 s in octets 6–8."""
    out = [header.ljust(GPS_HEADER, b"\0")[:GPS_HEADER]]
    for b, t in zip(blocks, times, strict=True):
        out.append(b + bytes(6) + tod_raw(t, 1 / 128, 24).to_bytes(3, "big") + b"\0")
    return b"".join(out)


def final(blocks: Sequence[bytes], times: Sequence[float], *, board: int = 1,
          line: int = 1) -> bytes:
    """Final records, one per block: count, board, line, day (``time // 86 400``), time of
    day in 0.01 s, the block, ``A5A5A5A5``."""
    out = []
    for b, t in zip(blocks, times, strict=True):
        head = struct.pack("!HBBB", 8 + len(b) + 4, board, line, int(t // 86400) & 0xFF)
        out.append(head + tod_raw(t, 0.01, 24).to_bytes(3, "big") + b + FINAL_PAD)
    return b"".join(out)


def llc_frame(block: bytes, sensor: int, *, dsap: int = 0x7E) -> bytes:
    """An IEEE 802.3 frame with an 802.2 LLC header (UI, control 0x03) carrying ``block``
    directly, padded to the 60-octet minimum."""
    body = bytes([dsap, dsap, 0x03]) + block
    head = bytes([1, 0, 0x5E, 0, 0, 1]) + bytes([2, 0, 0, 0, sensor >> 8 & 0xFF,
                                                 sensor & 0xFF]) + struct.pack("!H", len(body))
    return (head + body).ljust(60, b"\0")


def vlan(frame: bytes, tags: Sequence[tuple[int, int]]) -> bytes:
    """An Ethernet frame with ``(TPID, VLAN id)`` tags inserted after the MAC addresses
    (outermost first: ``[(0x88A8, s), (0x8100, c)]`` is QinQ)."""
    inserted = b"".join(struct.pack("!HH", tpid, vid & 0x0FFF) for tpid, vid in tags)
    return frame[:12] + inserted + frame[12:]


def sll(frame: bytes) -> bytes:
    """Linux cooked v1 (16 octets, protocol last) of an Ethernet II frame."""
    return struct.pack("!HHH8s", 0, 1, 6, frame[6:12]) + frame[12:]


def sll2(frame: bytes) -> bytes:
    """Linux cooked v2 (20 octets, protocol first) of an Ethernet II frame."""
    return struct.pack("!HHIHBB8s", int.from_bytes(frame[12:14], "big"), 0, 1, 1, 0, 6,
                       frame[6:12]) + frame[14:]


def udp_frames(blocks: Sequence[bytes], sensor: int) -> list[bytes]:
    """Ethernet/IPv4/UDP frames, one per block (:func:`mhtrack.io.asterix.writer.datagram`)."""
    return [datagram(b, sensor, i) for i, b in enumerate(blocks)]


def pcap(frames: Sequence[bytes], times: Sequence[float], *, link: int = 1,
         order: str = "<", nano: bool = False) -> bytes:
    """A libpcap file (µs or ns times, either byte order)."""
    magic, scale = (0xA1B23C4D, 10**9) if nano else (0xA1B2C3D4, 10**6)
    out = [struct.pack(order + "IHHiIII", magic, 2, 4, 0, 0, 65535, link)]
    for f, t in zip(frames, times, strict=True):
        ticks = round(t * scale)
        out.append(struct.pack(order + "IIII", ticks // scale, ticks % scale, len(f),
                               len(f)) + f)
    return b"".join(out)


def _block(btype: int, body: bytes, order: str) -> bytes:
    body += bytes(-len(body) % 4)
    return struct.pack(order + "II", btype, 12 + len(body)) + body + \
        struct.pack(order + "I", 12 + len(body))


def pcapng(frames: Sequence[bytes], times: Sequence[float], *, link: int = 1,
           order: str = "<", tsresol: int | None = None) -> bytes:
    """A pcapng file: section header, one interface (``tsresol`` the ``if_tsresol`` octet,
    default µs), one enhanced packet block per frame."""
    out = [_block(0x0A0D0D0A, struct.pack(order + "IHHq", 0x1A2B3C4D, 1, 0, -1), order)]
    opts = b""
    unit = 1e-6
    if tsresol is not None:
        opts = struct.pack(order + "HH", 9, 1) + bytes([tsresol, 0, 0, 0]) + bytes(4)
        unit = 2.0 ** -(tsresol & 0x7F) if tsresol & 0x80 else 10.0 ** -tsresol
    out.append(_block(1, struct.pack(order + "HHI", link, 0, 65535) + opts, order))
    for f, t in zip(frames, times, strict=True):
        ts = round(t / unit)
        out.append(_block(6, struct.pack(order + "IIIII", 0, ts >> 32, ts & 0xFFFFFFFF,
                                         len(f), len(f)) + f, order))
    return b"".join(out)
