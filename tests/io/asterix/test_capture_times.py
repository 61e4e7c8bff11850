"""Capture times of pcap and pcapng packets (the time axis takes the day from them):
microsecond and nanosecond pcap, pcapng with if_tsresol and if_tsoffset, and none for
simple packet blocks."""

from __future__ import annotations

import struct

import pytest

from mhtrack.io.asterix.framings import units
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.writer import datagram

BLOCK = bytes([48, 0, 3])  # an empty CAT048 block: the payload is all we look at
FRAME = datagram(BLOCK, 513, 1)


def _times(data: bytes, kind: str) -> list[float | None]:
    return [when for _, when, _ in units(data, kind, "x", {48}, Problems())]


@pytest.mark.parametrize(("magic", "unit"), [(0xA1B2C3D4, 1e-6), (0xA1B23C4D, 1e-9)])
def test_pcap(magic: int, unit: float) -> None:
    head = struct.pack("<IHHiIII", magic, 2, 4, 0, 0, 65535, 1)
    pkt = struct.pack("<IIII", 1_700_000_000, 250_000, len(FRAME), len(FRAME)) + FRAME
    assert _times(head + pkt, "pcap") == [1_700_000_000 + 250_000 * unit]


def _option(code: int, value: bytes) -> bytes:
    return struct.pack("<HH", code, len(value)) + value + bytes(-len(value) % 4)


def _block(btype: int, body: bytes) -> bytes:
    return struct.pack("<II", btype, 12 + len(body)) + body + struct.pack("<I", 12 + len(body))


def _pcapng(options: bytes, packets: list[bytes]) -> bytes:
    shb = _block(0x0A0D0D0A, struct.pack("<IHHq", 0x1A2B3C4D, 1, 0, -1))
    idb = _block(1, struct.pack("<HHI", 1, 0, 65535) + options)
    return shb + idb + b"".join(packets)


def _epb(ts: int) -> bytes:
    body = struct.pack("<IIIII", 0, ts >> 32, ts & 0xFFFFFFFF, len(FRAME), len(FRAME))
    return _block(6, body + FRAME + bytes(-len(FRAME) % 4))


def test_pcapng_resolutions_and_offset() -> None:
    ts = 1_700_000_000_123_456_789
    ns = _option(9, bytes([9])) + _option(0, b"")
    assert _times(_pcapng(ns, [_epb(ts)]), "pcapng") == [pytest.approx(ts * 1e-9)]
    assert _times(_pcapng(b"", [_epb(1_700_000_000_500_000)]), "pcapng") == [
        pytest.approx(1_700_000_000.5)]  # default: microseconds
    binary = _option(9, bytes([0x80 | 10])) + _option(14, struct.pack("<q", 3600))
    assert _times(_pcapng(binary, [_epb(1024 * 5)]), "pcapng") == [3605.0]
    spb = _block(3, struct.pack("<I", len(FRAME)) + FRAME + bytes(-len(FRAME) % 4))
    assert _times(_pcapng(b"", [spb]), "pcapng") == [None]


def test_pcapng_time_a_day_off_its_neighbours_is_not_used() -> None:
    """A timestamp with its bit 62 flipped (4.6e12 s in µs units) among packets a second
    apart: that packet's capture time is dropped and counted (``bad_time``, at its block's
    byte), the others are kept. Two packets in a row agreeing with each other but not
    with the last time taken (the clock set) are taken from the second on."""
    t0 = 1_700_000_000_000_000
    stamps = [t0, t0 + 1_000_000, (t0 + 2_000_000) | (1 << 62), t0 + 3_000_000]
    data = _pcapng(b"", [_epb(ts) for ts in stamps])
    problems = Problems()
    got = [when for _, when, _ in units(data, "pcapng", "x", {48}, problems)]
    assert got == [pytest.approx(1_700_000_000.0), pytest.approx(1_700_000_001.0), None,
                   pytest.approx(1_700_000_003.0)]
    assert problems.counts == {"bad_time": 1}
    head = len(_pcapng(b"", []))
    assert problems.first["bad_time"] == head + 2 * len(_epb(t0))
    # the clock set forward by two days: the first packet after the jump is refused,
    # the next one, agreeing with it, is taken and the check goes on from it
    jump = 2 * 86_400_000_000
    stamps = [t0, t0 + 1_000_000 + jump, t0 + 2_000_000 + jump, t0 + 3_000_000 + jump]
    problems = Problems()
    got = [when for _, when, _ in units(_pcapng(b"", [_epb(ts) for ts in stamps]),
                                        "pcapng", "x", {48}, problems)]
    assert got[1] is None
    assert got[2:] == [pytest.approx(1_700_172_802.0), pytest.approx(1_700_172_803.0)]
    assert problems.counts == {"bad_time": 1}


def test_pcapng_first_time_beyond_any_clock_is_not_used() -> None:
    """A damaged FIRST timestamp (bit 62: 4.6e12 s, after the year 2106) is not used and
    the packets after it keep theirs; before, it set the day of the whole axis and every
    later plot fell 4.6e12 s back."""
    t0 = 1_700_000_000_000_000
    stamps = [t0 | (1 << 62), t0 + 1_000_000, t0 + 2_000_000]
    problems = Problems()
    got = [when for _, when, _ in units(_pcapng(b"", [_epb(ts) for ts in stamps]),
                                        "pcapng", "x", {48}, problems)]
    assert got == [None, pytest.approx(1_700_000_001.0), pytest.approx(1_700_000_002.0)]
    assert problems.counts == {"bad_time": 1}
