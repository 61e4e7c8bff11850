"""Recordings of ASTERIX: which container a file is, recognised by its content, and the
ASTERIX bytes inside it.

* **pcap** (libpcap, magic ``a1b2c3d4``/``a1b23c4d`` either byte order) and **pcapng**
  (section header ``0a0d0d0a``): each captured packet's UDP payload, through the link
  layer (Ethernet with 802.1Q tags, raw IP, Linux cooked v1/v2, BSD loopback), IPv4 or
  IPv6, then UDP. Packets that are not UDP (ARP, TCP, IP fragments, other protocols) are
  skipped and counted.
* **raw**: anything else whose first octets are an ASTERIX data block header (a category
  libasterix knows, then a length of 3 octets or more that fits in the file) — a stream of
  data blocks back to back, as recorders and ``mhtrack export … .ast`` write it.

Parsed with :mod:`struct` (the container formats are a few fixed headers; no dependency is
worth it). Each payload comes with its byte offset in the file, so that every problem
found later can name where it is.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator

from mhtrack.errors import InputError
from mhtrack.io.asterix.problems import Problems

PCAP_MAGICS = {b"\xd4\xc3\xb2\xa1": "<", b"\xa1\xb2\xc3\xd4": ">",
               b"\x4d\x3c\xb2\xa1": "<", b"\xa1\xb2\x3c\x4d": ">"}
PCAPNG_MAGIC = b"\x0a\x0d\x0d\x0a"
#: pcap link types read (LINKTYPE_* values of the tcpdump registry).
LINK_ETHERNET, LINK_NULL, LINK_SLL, LINK_SLL2 = 1, 0, 113, 276
LINK_RAW = (101, 12, 14)
ETH_IPV4, ETH_IPV6, ETH_VLAN = 0x0800, 0x86DD, (0x8100, 0x88A8)
UDP = 17


def container(data: bytes, name: str, known_categories: set[int]) -> str:
    """``"pcap"``, ``"pcapng"`` or ``"raw"`` by the file's first octets, else an
    :class:`InputError` naming byte 0."""
    head = data[:4]
    if head in PCAP_MAGICS:
        return "pcap"
    if head == PCAPNG_MAGIC:
        return "pcapng"
    if len(data) >= 3:
        cat, length = data[0], int.from_bytes(data[1:3], "big")
        if cat in known_categories and 3 <= length <= len(data):
            return "raw"
    shown = f"starts with {data[:8].hex(' ')}" if data else "the file is empty"
    raise InputError(f"{name}: byte 0: not an ASTERIX recording ({shown}; "
                     "expected a pcap or pcapng header, or an ASTERIX data block: a "
                     "category, then a length of 3 octets or more that fits in the file)",
                     file=name)


def payloads(data: bytes, kind: str, name: str, problems: Problems
             ) -> Iterator[tuple[int, bytes]]:
    """``(offset in the file, ASTERIX bytes)`` of each datagram (raw: the whole file)."""
    for offset, payload, _ in datagrams(data, kind, name, problems):
        yield offset, payload


def datagrams(data: bytes, kind: str, name: str, problems: Problems
              ) -> Iterator[tuple[int, bytes, float | None]]:
    """``(offset in the file, ASTERIX bytes, capture time)`` of each datagram; the
    capture time is POSIX seconds (pcap, pcapng), ``None`` where the container has none
    (raw: the whole file, pcapng simple packet blocks). ``data`` may be a ``bytes`` or
    an ``mmap`` of the file."""
    if kind == "raw":
        yield 0, data, None
    elif kind == "pcap":
        yield from _pcap(data, name, problems)
    else:
        yield from _pcapng(data, name, problems)


def _pcap(data: bytes, name: str, problems: Problems
          ) -> Iterator[tuple[int, bytes, float | None]]:
    if len(data) < 24:
        raise InputError(f"{name}: byte 0: pcap global header cut short ({len(data)} of "
                         "24 octets)", file=name)
    e = PCAP_MAGICS[data[:4]]
    link = struct.unpack_from(e + "I", data, 20)[0] & 0xFFFF
    _check_link(link, name, 20)
    rec = struct.Struct(e + "IIII")
    frac = 1e-9 if data[:4] in (b"\x4d\x3c\xb2\xa1", b"\xa1\xb2\x3c\x4d") else 1e-6
    pos = 24
    while pos < len(data):
        if pos + 16 > len(data):
            problems.add("truncated_packet", pos)
            return
        sec, sub, incl, _ = rec.unpack_from(data, pos)
        start = pos + 16
        if start + incl > len(data):
            problems.add("truncated_packet", pos)
            return
        found = _udp(data, start, start + incl, link)
        if found is None:
            problems.add("non_udp", pos)
        else:
            yield (*found, sec + sub * frac)
        pos = start + incl


def _pcapng(data: bytes, name: str, problems: Problems
            ) -> Iterator[tuple[int, bytes, float | None]]:
    e = "<"
    links: list[int] = []
    clocks: list[tuple[float, float]] = []  # per interface: (seconds per unit, offset s)
    pos = 0
    while pos < len(data):
        if pos + 12 > len(data):
            problems.add("truncated_packet", pos)
            return
        btype = struct.unpack_from(e + "I", data, pos)[0]
        if btype == 0x0A0D0D0A:  # section header: its byte-order magic sets the order
            bom = data[pos + 8:pos + 12]
            e = "<" if bom == b"\x4d\x3c\x2b\x1a" else ">" if bom == b"\x1a\x2b\x3c\x4d" \
                else ""
            if not e:
                raise InputError(f"{name}: byte {pos + 8}: pcapng section header without "
                                 "its byte-order magic 1a2b3c4d", file=name)
            links, clocks = [], []
        total = struct.unpack_from(e + "I", data, pos + 4)[0]
        if total < 12 or pos + total > len(data):
            problems.add("truncated_packet", pos)
            return
        if btype == 1:  # interface description: its link type
            link = struct.unpack_from(e + "H", data, pos + 8)[0]
            _check_link(link, name, pos + 8)
            links.append(link)
            clocks.append(_clock(data, e, pos + 16, pos + total - 4))
        elif btype in (6, 3, 2):  # enhanced, simple, obsolete packet blocks
            stamped = btype != 3
            if btype == 6:
                iface, cap = struct.unpack_from(e + "I", data, pos + 8)[0], \
                    struct.unpack_from(e + "I", data, pos + 20)[0]
                start = pos + 28
            elif btype == 3:
                iface, cap, start = 0, total - 16, pos + 12
            else:
                iface = struct.unpack_from(e + "H", data, pos + 8)[0]
                cap = struct.unpack_from(e + "I", data, pos + 20)[0]
                start = pos + 28
            if iface >= len(links):
                raise InputError(f"{name}: byte {pos}: pcapng packet on interface {iface}, "
                                 f"which no interface description block declared", file=name)
            end = min(start + cap, pos + total - 4)
            found = _udp(data, start, end, links[iface])
            if found is None:
                problems.add("non_udp", pos)
            else:
                when = None
                if stamped:
                    hi, lo = struct.unpack_from(e + "II", data, pos + 12)
                    unit, offset = clocks[iface]
                    when = ((hi << 32) | lo) * unit + offset
                yield (*found, when)
        pos += total


def _clock(data: bytes, e: str, pos: int, end: int) -> tuple[float, float]:
    """``(seconds per timestamp unit, offset s)`` of a pcapng interface from its options
    ``if_tsresol`` (9: 10^-v, or 2^-v with the top bit set; default 10^-6) and
    ``if_tsoffset`` (14: seconds added)."""
    unit, offset = 1e-6, 0.0
    while pos + 4 <= end:
        code, length = struct.unpack_from(e + "HH", data, pos)
        if code == 0:
            break
        if code == 9 and length >= 1:
            v = data[pos + 4]
            unit = 2.0 ** -(v & 0x7F) if v & 0x80 else 10.0 ** -v
        elif code == 14 and length >= 8:
            offset = float(struct.unpack_from(e + "q", data, pos + 4)[0])
        pos += 4 + (length + 3) // 4 * 4
    return unit, offset


def _check_link(link: int, name: str, offset: int) -> None:
    if link not in (LINK_ETHERNET, LINK_NULL, LINK_SLL, LINK_SLL2, *LINK_RAW):
        raise InputError(f"{name}: byte {offset}: capture link type {link} is not read "
                         "(Ethernet 1, raw IP 101/12/14, Linux cooked 113/276, BSD "
                         "loopback 0)", file=name)


def _udp(data: bytes, start: int, end: int, link: int) -> tuple[int, bytes] | None:
    """The UDP payload of the packet ``data[start:end]``, or ``None``."""
    pos, proto = start, None
    if link == LINK_ETHERNET:
        if end - pos < 14:
            return None
        proto, pos = int.from_bytes(data[pos + 12:pos + 14], "big"), pos + 14
        while proto in ETH_VLAN and end - pos >= 4:
            proto, pos = int.from_bytes(data[pos + 2:pos + 4], "big"), pos + 4
    elif link == LINK_SLL:
        if end - pos < 16:
            return None
        proto, pos = int.from_bytes(data[pos + 14:pos + 16], "big"), pos + 16
    elif link == LINK_SLL2:
        if end - pos < 20:
            return None
        proto, pos = int.from_bytes(data[pos:pos + 2], "big"), pos + 20
    elif link == LINK_NULL:
        if end - pos < 4:
            return None
        family = data[pos] or data[pos + 3]
        proto, pos = (ETH_IPV4 if family == 2 else ETH_IPV6), pos + 4
    if pos >= end:
        return None
    version = data[pos] >> 4
    if proto is None:
        proto = ETH_IPV4 if version == 4 else ETH_IPV6 if version == 6 else None
    if proto == ETH_IPV4 and version == 4 and end - pos >= 20:
        ihl = (data[pos] & 0x0F) * 4
        frag = int.from_bytes(data[pos + 6:pos + 8], "big")
        if data[pos + 9] != UDP or frag & 0x3FFF or ihl < 20:
            return None  # other protocol, or an IP fragment
        pos += ihl
    elif proto == ETH_IPV6 and version == 6 and end - pos >= 40:
        if data[pos + 6] != UDP:
            return None
        pos += 40
    else:
        return None
    if end - pos < 8:
        return None
    length = int.from_bytes(data[pos + 4:pos + 6], "big")
    stop = min(end, pos + length) if length >= 8 else end
    return pos + 8, data[pos + 8:stop]


def blocks(payload: bytes, base: int, problems: Problems
           ) -> Iterator[tuple[int, int, bytes]]:
    """``(file offset, category, records)`` of each data block of a payload (its header
    of category and 2-octet length framing it). A length below 3 skips the rest of the
    payload, a length beyond it the block (both counted)."""
    pos, n = 0, len(payload)
    while pos < n:
        if n - pos < 3:
            problems.add("trailing", base + pos, n - pos)
            return
        cat = payload[pos]
        length = (payload[pos + 1] << 8) | payload[pos + 2]
        if length < 3:
            problems.add("bad_length", base + pos)
            return
        if pos + length > n:
            problems.add("truncated_block", base + pos)
            return
        yield base + pos, cat, payload[pos + 3:pos + length]
        pos += length
