"""The ASTERIX octets inside one captured packet, through its link layer (docs/file-formats.md,
"ASTERIX recordings").

Link types read (LINKTYPE_* values of the tcpdump registry): Ethernet (1), raw IP (101, 12,
14), Linux cooked v1 (113, a 16-octet header whose last two octets are the protocol) and v2
(276, 20 octets, protocol first), BSD loopback (0, a 4-octet address family).

On Ethernet the two octets after the MAC addresses are an EtherType when ≥ 0x0600 (IEEE
802.3 clause 3.2.6) and a length otherwise:

* EtherType: 802.1Q (0x8100) and 802.1ad/QinQ (0x88A8, 0x9100) tags of 4 octets each are
  stepped over, then IPv4 (0x0800) or IPv6 (0x86DD);
* length: an IEEE 802.3 frame with an IEEE 802.2 LLC header — DSAP, SSAP, then a control
  field of 1 octet for unnumbered frames (its two low bits 11) or 2 octets otherwise; with
  DSAP = SSAP = 0xAA a SNAP header follows (3-octet OUI, 2-octet EtherType → IP as above);
  any other SAP carries ASTERIX directly (as radar heads on a LAN without IP send it). The
  length field bounds the data (the frame may be padded to 60 octets).

IPv4 (RFC 791: header length IHL × 4, protocol 17, fragments skipped) or IPv6 (RFC 8200:
hop-by-hop, routing and destination-options extension headers stepped over, next header 17),
then UDP (RFC 768: 8 octets, its length field bounding the payload).
"""

from __future__ import annotations

LINK_NULL, LINK_ETHERNET, LINK_SLL, LINK_SLL2 = 0, 1, 113, 276
LINK_RAW = (101, 12, 14)
#: Every link type read.
LINKS = (LINK_NULL, LINK_ETHERNET, LINK_SLL, LINK_SLL2, *LINK_RAW)
ETH_IPV4, ETH_IPV6 = 0x0800, 0x86DD
#: 802.1Q, 802.1ad (QinQ) and the older QinQ tag 0x9100.
ETH_TAGS = (0x8100, 0x88A8, 0x9100)
#: IPv6 extension headers stepped over: hop-by-hop, routing, destination options.
IPV6_EXTENSIONS = (0, 43, 60)
UDP = 17
#: The LLC SAP of SNAP (IEEE 802 overview, clause 10).
SNAP_SAP = 0xAA


def payload(data: bytes, start: int, end: int, link: int) -> tuple[int, bytes] | None:
    """``(file offset, octets)`` of the ASTERIX carried by the packet ``data[start:end]``
    (UDP payload, or the data of an 802.3/LLC frame), or ``None`` for a packet that carries
    none (ARP, TCP, an IP fragment, a frame cut short)."""
    pos, proto = start, None
    if link == LINK_ETHERNET:
        if end - pos < 14:
            return None
        proto, pos = _u16(data, pos + 12), pos + 14
        while proto in ETH_TAGS and end - pos >= 4:
            proto, pos = _u16(data, pos + 2), pos + 4
        if proto < 0x0600:
            return _llc(data, pos, min(end, pos + proto))
    elif link == LINK_SLL:
        if end - pos < 16:
            return None
        proto, pos = _u16(data, pos + 14), pos + 16
    elif link == LINK_SLL2:
        if end - pos < 20:
            return None
        proto, pos = _u16(data, pos), pos + 20
    elif link == LINK_NULL:
        if end - pos < 4:
            return None
        family = data[pos] or data[pos + 3]
        proto, pos = (ETH_IPV4 if family == 2 else ETH_IPV6), pos + 4
    return _ip(data, pos, end, proto)


def _u16(data: bytes, pos: int) -> int:
    return (data[pos] << 8) | data[pos + 1]


def _llc(data: bytes, pos: int, end: int) -> tuple[int, bytes] | None:
    """The data of an 802.2 LLC frame (SNAP → IP)."""
    if end - pos < 3:
        return None
    dsap, ssap, control = data[pos], data[pos + 1], data[pos + 2]
    pos += 3 if control & 0x03 == 0x03 else 4
    if dsap == SNAP_SAP and ssap == SNAP_SAP:
        if end - pos < 5:
            return None
        return _ip(data, pos + 5, end, _u16(data, pos + 3))
    if pos >= end:
        return None
    return pos, bytes(data[pos:end])


def _ip(data: bytes, pos: int, end: int, proto: int | None) -> tuple[int, bytes] | None:
    if pos >= end:
        return None
    version = data[pos] >> 4
    if proto is None:
        proto = ETH_IPV4 if version == 4 else ETH_IPV6 if version == 6 else None
    if proto == ETH_IPV4 and version == 4 and end - pos >= 20:
        ihl = (data[pos] & 0x0F) * 4
        if data[pos + 9] != UDP or _u16(data, pos + 6) & 0x3FFF or ihl < 20:
            return None  # other protocol, or an IP fragment
        pos += ihl
    elif proto == ETH_IPV6 and version == 6 and end - pos >= 40:
        nxt, pos = data[pos + 6], pos + 40
        while nxt in IPV6_EXTENSIONS and end - pos >= 8:
            nxt, pos = data[pos], pos + 8 * (data[pos + 1] + 1)
        if nxt != UDP:
            return None
    else:
        return None
    if end - pos < 8:
        return None
    length = _u16(data, pos + 4)
    stop = min(end, pos + length) if length >= 8 else end
    return pos + 8, bytes(data[pos + 8:stop])
