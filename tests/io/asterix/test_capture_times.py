"""Capture times of pcap and pcapng packets (the time axis takes the day from them):
microsecond and nanosecond pcap, pcapng with if_tsresol and if_tsoffset, and none for
simple packet blocks."""

from __future__ import annotations

import struct

import pytest

from mhtrack.io.asterix.capture import START, start_time
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
    # the clock set forward by two days after the first START packets: the first packet
    # after the jump is refused, the next one, agreeing with it, is taken and the check
    # goes on from it
    jump = 2 * 86_400_000_000
    stamps = [t0 + k * 1_000_000 + (jump if k > START else 0) for k in range(START + 4)]
    problems = Problems()
    got = [when for _, when, _ in units(_pcapng(b"", [_epb(ts) for ts in stamps]),
                                        "pcapng", "x", {48}, problems)]
    assert got[:START + 1] == [pytest.approx(ts * 1e-6) for ts in stamps[:START + 1]]
    assert got[START + 1] is None
    assert got[START + 2:] == [pytest.approx(ts * 1e-6) for ts in stamps[START + 2:]]
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


@pytest.mark.parametrize("bad", range(START + 1))
def test_pcapng_time_damaged_within_range_is_outvoted_wherever_it_comes(bad: int) -> None:
    """A timestamp with bit 40 flipped (2⁴⁰ µs: 12.7 days off, still within [0, 2³²) s) in
    any of the first packets, the very first included: that packet's time is dropped and
    counted, every other packet keeps its own. Before, a damaged first time was taken and
    the next packet refused in its stead (the check started from the first time)."""
    t0 = 1_700_000_000_000_000
    stamps = [t0 + k * 1_000_000 for k in range(START + 3)]
    stamps[bad] ^= 1 << 40
    assert abs(stamps[bad] - t0) * 1e-6 > 86_400 and stamps[bad] * 1e-6 < 2**32
    problems = Problems()
    data = _pcapng(b"", [_epb(ts) for ts in stamps])
    got = [when for _, when, _ in units(data, "pcapng", "x", {48}, problems)]
    want = [None if k == bad else pytest.approx(1_700_000_000.0 + k)
            for k in range(len(stamps))]
    assert got == want
    assert problems.counts == {"bad_time": 1}
    assert problems.first["bad_time"] == len(_pcapng(b"", [])) + bad * len(_epb(t0))


def test_start_time_is_the_median_of_the_first_packets() -> None:
    """Worked by hand: the median of the first five (the upper one of an even count);
    later times have no say."""
    assert start_time([]) is None
    assert start_time([7.0]) == 7.0
    assert start_time([5.0, 1.0]) == 5.0
    assert start_time([9e9, 3.0, 1.0, 2.0, 4.0, 9e9, 9e9, 9e9]) == 3.0


def test_pcap_damaged_first_time_is_the_packet_refused() -> None:
    """pcap's reader starts from the same median: a first packet 12.7 days off the next
    four is the one refused (damaged framing), not the four after it."""
    head = struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)
    secs = [1_700_000_000 + k for k in range(5)]
    secs[0] ^= 1 << 20
    pkts = b"".join(struct.pack("<IIII", s, 0, len(FRAME), len(FRAME)) + FRAME
                    for s in secs)
    problems = Problems()
    got = [when for _, when, _ in units(head + pkts, "pcap", "x", {48}, problems)]
    assert got == [float(s) for s in secs[1:]]
    assert problems.counts["resync"] == 1
