"""How ASTERIX data blocks are framed in a recording, recognised by content, and the units
they unwrap to: ``(byte offset of the payload in the file, capture time or None, payload)``
(docs/file-formats.md, "ASTERIX recordings").

Layouts (octets; multi-octet fields big-endian unless said):

* **pcap** (libpcap: magic ``a1b2c3d4`` µs / ``a1b23c4d`` ns, either byte order; 24-octet
  header, then per packet ``ts_sec, ts_frac, incl_len, orig_len`` and the packet) and
  **pcapng** (blocks of type, total length, body, total length again; interface
  descriptions give the link type, ``if_tsresol``, option 9: 10⁻ⁿ s, or 2⁻ⁿ s with the
  high bit set, and ``if_tsoffset``, option 14: seconds added; enhanced packet blocks a
  64-bit timestamp in those units; simple packet blocks none). Time: POSIX s.
  Inside each packet: :mod:`mhtrack.io.asterix.link`.
* **ORADIS**: per record 2 octets byte count (the whole record, header included), 4 octets
  of time (whose unit no public source gives: not read), then one or more data blocks;
  found as a file or as the payload of UDP datagrams (:func:`unwrap`).
* **GPS** recorder format: a 2 200-octet file header, then each data block followed by 10
  octets whose octets 6–8 are the time of day in 1/128 s. Time: seconds of the day, plus
  a day each time it steps back by more than 12 h (midnight), so that it never goes back.
* **Final** format: per record 2 octets byte count (the whole record), board number, line
  number, recording day, 3 octets time of day in 0.01 s, one or more data blocks, then the
  padding ``A5 A5 A5 A5``. Time: ``day × 86 400 + time of day`` s (the day a counter of the
  recording, not a date).
* **raw**: data blocks back to back (category, 2-octet length ≥ 3). Time: ``None``.

Layouts of ORADIS, GPS and Final as the Croatia Control ``asterix`` decoder reads them
(``asterixgpssubformat``, ``asterixfinalsubformat``; facts only).

Damage (a length beyond the data, a missing trailer, a time beyond a day; a pcap packet
empty, more than a day from the one before, or whose captured length is neither its
length nor the snap length; capture times: :mod:`~mhtrack.io.asterix.capture`) is
skipped at the level of one record: the reader moves on to the next offset where
:data:`~mhtrack.io.asterix.resync.CONFIRM` records in a row are valid (or valid ones end
the file), counts one ``resync`` and the octets skipped
(:mod:`mhtrack.io.asterix.resync`). It raises only on the file's own headers: a file that
is no recording, a capture link type not read (:class:`InputError`, naming the byte). A
raw stream has no framing of its own beyond category and length, so its blocks are
judged by their content too when the reader is given a ``fits`` check
(:func:`~mhtrack.io.asterix.resync.judged`): a block is valid only when its records, item
lengths read from its FSPEC by the category's UAP, end exactly at its end. A damaged
block length that lands on octets framed like a block is then found out, and reading
resumes at the good blocks it would have covered.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Iterator
from itertools import chain

from mhtrack.errors import InputError
from mhtrack.io.asterix.capture import START, CaptureClock, plausible, start_time
from mhtrack.io.asterix.link import LINKS, payload
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.resync import judged, walk
from mhtrack.io.asterix.timeaxis import DAY_S

#: ``(offset of the payload in the file, time s or None, ASTERIX octets)``.
Unit = tuple[int, float | None, bytes]
PCAP_MAGICS = {b"\xd4\xc3\xb2\xa1": ("<", 1e-6), b"\xa1\xb2\xc3\xd4": (">", 1e-6),
               b"\x4d\x3c\xb2\xa1": ("<", 1e-9), b"\xa1\xb2\x3c\x4d": (">", 1e-9)}
PCAPNG_MAGIC = b"\x0a\x0d\x0d\x0a"
GPS_HEADER, GPS_TRAILER, ORADIS_HEADER, FINAL_HEADER = 2200, 10, 6, 8
FINAL_PAD = b"\xa5\xa5\xa5\xa5"
#: Stream framings tried on a file with no pcap magic, in order of preference at a tie.
STREAMS = ("final", "oradis", "gps", "raw")
#: Records checked from the start to recognise a stream framing.
PROBE = 16
#: Octets searched for the first valid record of a file whose first records are damaged.
SEARCH = 4096
#: pcap packets longer than this are damage (the largest snap length tcpdump uses).
MAX_PACKET = 262144


def blocks_fit(data: bytes, start: int, end: int, cats: set[int]) -> bool:
    """``data[start:end]`` is one or more whole data blocks of known categories."""
    pos = start
    while pos < end:
        if end - pos < 3 or data[pos] not in cats:
            return False
        length = (data[pos + 1] << 8) | data[pos + 2]
        if length < 3 or pos + length > end:
            return False
        pos += length
    return pos == end and end > start


def _u16(data: bytes, pos: int) -> int:
    return (data[pos] << 8) | data[pos + 1]


def _final_at(data: bytes, p: int, cats: set[int]) -> int:
    n = len(data)
    if n - p < FINAL_HEADER + 3 + 4:
        return 0
    count = _u16(data, p)
    tod = int.from_bytes(data[p + 5:p + 8], "big")
    if count < FINAL_HEADER + 7 or p + count > n or tod >= 8640000 \
            or data[p + count - 4:p + count] != FINAL_PAD:
        return 0
    return count if blocks_fit(data, p + FINAL_HEADER, p + count - 4, cats) else 0


def _oradis_at(data: bytes, p: int, cats: set[int]) -> int:
    if len(data) - p < ORADIS_HEADER + 3:
        return 0
    count = _u16(data, p)
    if count < ORADIS_HEADER + 3 or p + count > len(data):
        return 0
    return count if blocks_fit(data, p + ORADIS_HEADER, p + count, cats) else 0


def _gps_at(data: bytes, p: int, cats: set[int]) -> int:
    if p < GPS_HEADER or len(data) - p < 3 + GPS_TRAILER or data[p] not in cats:
        return 0
    length = _u16(data, p + 1)
    end = p + length + GPS_TRAILER
    if length < 3 or end > len(data) or int.from_bytes(data[end - 4:end - 1], "big") \
            >= 128 * 86400:
        return 0
    return length + GPS_TRAILER


def _raw_at(data: bytes, p: int, cats: set[int]) -> int:
    if len(data) - p < 3 or data[p] not in cats:
        return 0
    length = _u16(data, p + 1)
    return length if length >= 3 and p + length <= len(data) else 0


_AT: dict[str, Callable[[bytes, int, set[int]], int]] = {
    "final": _final_at, "oradis": _oradis_at, "gps": _gps_at, "raw": _raw_at}
_START = {"final": 0, "oradis": 0, "gps": GPS_HEADER, "raw": 0}


def _chain(data: bytes, kind: str, p: int, cats: set[int]) -> int:
    """Records that chain from offset ``p`` (at most :data:`PROBE`; :data:`PROBE` when the
    chain reaches the end of the file)."""
    at = _AT[kind]
    for k in range(PROBE):
        if p == len(data):
            return PROBE if k else 0
        step = at(data, p, cats)
        if not step:
            return k
        p += step
    return PROBE


def _probe(data: bytes, kind: str, cats: set[int], fallback: bool) -> int:
    """How well the file reads as ``kind``: the records chained from its start; with
    ``fallback``, when fewer than two do, :data:`PROBE` − 1 if a full chain (:data:`PROBE`
    records, or two or more to the end of the file) starts within the next :data:`SEARCH`
    octets (the first records damaged)."""
    start = _START[kind]
    score = _chain(data, kind, start, cats)
    if score >= 2 or len(data) <= start or not fallback:
        return score
    for q in range(start + 1, min(len(data), start + SEARCH)):
        if _AT[kind](data, q, cats) and _chain(data, kind, q, cats) == PROBE:
            return PROBE - 1
    return score


def recognise(data: bytes, name: str, cats: set[int]) -> str:
    """``"pcap"``, ``"pcapng"``, ``"final"``, ``"oradis"``, ``"gps"`` or ``"raw"`` by the
    file's content (stream framings: the one whose records chain furthest from the start,
    :data:`STREAMS` order at a tie; when none chains two, the one whose full chain starts
    within :data:`SEARCH` octets), else an :class:`InputError` naming byte 0."""
    if data[:4] in PCAP_MAGICS:
        return "pcap"
    if data[:4] == PCAPNG_MAGIC:
        return "pcapng"
    for fallback in (False, True):  # records chained from the start first
        best, kind = 0, ""
        for k in STREAMS:
            if (score := _probe(data, k, cats, fallback)) > best:
                best, kind = score, k
        if best >= 2 or (kind and fallback):
            return kind
    shown = f"starts with {data[:8].hex(' ')}" if data else "the file is empty"
    raise InputError(f"{name}: byte 0: not an ASTERIX recording ({shown}; expected pcap, "
                     "pcapng, ORADIS, GPS or Final records, or ASTERIX data blocks)",
                     file=name)


def units(data: bytes, kind: str, name: str, cats: set[int], problems: Problems,
          fits: Callable[[bytes], bool] | None = None) -> Iterator[Unit]:
    """Every unit of a recording of framing ``kind`` (:func:`recognise`); ORADIS inside
    UDP is unwrapped too (:func:`unwrap`). Damage is counted in ``problems``. ``fits``
    (a data block, header included -> whether its records fill it) judges the blocks of
    a raw stream by their content too (:func:`~mhtrack.io.asterix.resync.judged`)."""
    if kind == "pcap":
        inner = _pcap(data, name, problems)
    elif kind == "pcapng":
        inner = _pcapng(data, name, problems)
    else:
        inner = _stream(data, kind, cats, problems, fits)
    for offset, time, octets in inner:
        yield from unwrap(offset, time, octets, cats)


def unwrap(offset: int, time: float | None, octets: bytes, cats: set[int]
           ) -> list[Unit]:
    """A datagram's payload as ASTERIX units: itself when it starts with a data block of a
    known category; its records' data blocks when it is a chain of ORADIS records that fills
    it exactly; else itself (the block reader counts what is wrong)."""
    if octets and octets[0] in cats and _raw_at(octets, 0, cats):
        return [(offset, time, octets)]
    out, p = [], 0
    while p < len(octets) and (step := _oradis_at(octets, p, cats)):
        out.append((offset + p + ORADIS_HEADER, time, octets[p + ORADIS_HEADER:p + step]))
        p += step
    return out if out and p == len(octets) else [(offset, time, octets)]


def _stream(data: bytes, kind: str, cats: set[int], problems: Problems,
            fits: Callable[[bytes], bool] | None = None) -> Iterator[Unit]:
    if kind == "gps" and len(data) < GPS_HEADER:
        problems.add("skipped_octets", 0, len(data))
        return
    check = _AT[kind]
    at = judged(data, lambda q: _raw_at(data, q, cats), fits) \
        if kind == "raw" and fits is not None else lambda q: check(data, q, cats)
    day, last = 0, None  # GPS: days counted where its time of day steps back over 12 h
    for p, step in walk(data, _START[kind], at, problems):
        if kind == "final":
            tod = int.from_bytes(data[p + 5:p + 8], "big") * 0.01
            yield p + FINAL_HEADER, data[p + 4] * DAY_S + tod, \
                data[p + FINAL_HEADER:p + step - 4]
        elif kind == "oradis":
            yield p + ORADIS_HEADER, None, data[p + ORADIS_HEADER:p + step]
        elif kind == "gps":
            end = p + step
            tod = int.from_bytes(data[end - 4:end - 1], "big") / 128.0
            if last is not None and tod < last - DAY_S / 2:
                day += 1
            last = tod
            yield p, tod + day * DAY_S, data[p:end - GPS_TRAILER]
        else:
            yield p, None, data[p:p + step]


def _check_link(link: int, name: str, offset: int) -> None:
    if link not in LINKS:
        raise InputError(f"{name}: byte {offset}: capture link type {link} is not read "
                         "(Ethernet 1, raw IP 101/12/14, Linux cooked 113/276, BSD "
                         "loopback 0)", file=name)


def _pcap(data: bytes, name: str, problems: Problems) -> Iterator[Unit]:
    if len(data) < 24:
        raise InputError(f"{name}: byte 0: pcap global header cut short ({len(data)} of "
                         "24 octets)", file=name)
    e, unit = PCAP_MAGICS[data[:4]]
    snap, link = struct.unpack_from(e + "II", data, 16)
    link &= 0xFFFF
    _check_link(link, name, 20)
    limit = min(snap, MAX_PACKET) if snap else MAX_PACKET
    rec = struct.Struct(e + "IIII")
    frac_max = round(1 / unit)

    last = [-1]  # the seconds of the last packet taken (-1: none yet)

    def at(p: int) -> int:
        if len(data) - p < 16:
            return 0
        sec, frac, incl, orig = rec.unpack_from(data, p)
        ok = 0 < incl <= limit and (orig == incl or incl == snap < orig) and frac < frac_max \
            and p + 16 + incl <= len(data) and (last[0] < 0 or abs(sec - last[0]) <= DAY_S)
        return 16 + incl if ok else 0

    secs, q = [], 24  # to begin with, the median time of the first packets chained
    while len(secs) < START and (step := at(q)):
        secs.append(rec.unpack_from(data, q)[0])
        q += step
    if secs:
        last[0] = start_time(secs)
    for p, step in walk(data, 24, at, problems):
        sec, frac, _, _ = rec.unpack_from(data, p)
        nxt = p + step
        if nxt + 16 > len(data) or abs(rec.unpack_from(data, nxt)[0] - sec) <= DAY_S:
            last[0] = sec  # the reference moves on only where the next packet agrees
        found = payload(data, p + 16, p + step, link)
        if found is None:
            problems.add("non_udp", p)
        else:
            yield found[0], sec + frac * unit, found[1]


def _clock(data: bytes, e: str, start: int, end: int) -> tuple[float, float]:
    """``(seconds per timestamp unit, offset s)`` of a pcapng interface from its options
    ``if_tsresol`` (code 9: 10⁻ᵛ s, or 2⁻ᵛ s with the high bit set; default 10⁻⁶) and
    ``if_tsoffset`` (code 14: seconds added to every timestamp)."""
    unit, offset, p = 1e-6, 0.0, start
    while end - p >= 4:
        code, length = struct.unpack_from(e + "HH", data, p)
        if code == 0:
            break
        if code == 9 and length >= 1:
            v = data[p + 4]
            unit = 2.0 ** -(v & 0x7F) if v & 0x80 else 10.0 ** -v
        elif code == 14 and length >= 8 and p + 12 <= end:
            offset = float(struct.unpack_from(e + "q", data, p + 4)[0])
        p += 4 + length + (-length % 4)
    return unit, offset


def _pcapng(data: bytes, name: str, problems: Problems) -> Iterator[Unit]:
    """The units of a pcapng file, their capture times checked (:class:`CaptureClock`,
    started from the median of the first :data:`START` plausible ones)."""
    clock = CaptureClock(problems)
    packets = _pcapng_packets(data, name, problems)
    ahead: list[tuple[int, float | None, int, bytes]] = []
    for packet in packets:  # read ahead to the first START plausible times
        ahead.append(packet)
        if sum(t is not None and plausible(t) for _, t, _, _ in ahead) == START:
            break
    clock.start([t for _, t, _, _ in ahead])
    for offset, t, block, octets in chain(ahead, packets):
        yield offset, clock.take(t, block), octets


def _pcapng_packets(data: bytes, name: str, problems: Problems
                    ) -> Iterator[tuple[int, float | None, int, bytes]]:
    """``(offset of the payload, capture time as stamped or None, offset of the block,
    payload)`` of each packet carrying a payload."""
    state = {"e": "<"}
    links: list[tuple[int, tuple[float, float]]] = []

    def at(p: int) -> int:
        if len(data) - p < 12:
            return 0
        e = state["e"]
        if data[p:p + 4] == PCAPNG_MAGIC:
            bom = data[p + 8:p + 12]
            e = "<" if bom == b"\x4d\x3c\x2b\x1a" else ">" if bom == b"\x1a\x2b\x3c\x4d" \
                else ""
            if not e:
                return 0
        total = struct.unpack_from(e + "I", data, p + 4)[0]
        if total < 12 or total % 4 or p + total > len(data) \
                or struct.unpack_from(e + "I", data, p + total - 4)[0] != total:
            return 0
        return total

    for p, total in walk(data, 0, at, problems):
        if data[p:p + 4] == PCAPNG_MAGIC:
            state["e"] = "<" if data[p + 8] == 0x4D else ">"
            links = []
            continue
        e = state["e"]
        btype = struct.unpack_from(e + "I", data, p)[0]
        if btype == 1 and total >= 20:
            link = struct.unpack_from(e + "H", data, p + 8)[0]
            _check_link(link, name, p + 8)
            links.append((link, _clock(data, e, p + 16, p + total - 4)))
        elif btype in (6, 3, 2) and total >= 16:
            if btype == 3:
                iface, cap, start, ts = 0, total - 16, p + 12, None
            else:
                iface = struct.unpack_from(e + ("I" if btype == 6 else "H"), data, p + 8)[0]
                hi, lo, cap = struct.unpack_from(e + "III", data, p + 12)
                start, ts = p + 28, (hi << 32) | lo
            if iface >= len(links):
                problems.add("non_udp", p, detail=f"packet on interface {iface}, which no "
                             "interface description block declared")
                continue
            link, (unit, offset) = links[iface]
            found = payload(data, start, min(start + cap, p + total - 4), link)
            if found is None:
                problems.add("non_udp", p)
            else:
                yield found[0], None if ts is None else ts * unit + offset, p, found[1]
