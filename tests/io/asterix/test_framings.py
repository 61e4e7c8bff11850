"""Framings recognised by content and unwrapped (io/asterix/framings.py, link.py): round
trips through every framing written by wrap.py, checked by libasterix and by pyasteryx
(independent: its own CAT048 tables and pcap reader); the former container path on the
real capture; damage (bit flips, truncations, garbage) skipped per record."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import mhtrack.io.asterix._lib as _lib
from mhtrack.errors import InputError
from mhtrack.io.asterix import wrap
from mhtrack.io.asterix.decode import plot_row
from mhtrack.io.asterix.encode import encode_blocks, lsb, plot_messages
from mhtrack.io.asterix.framings import recognise, units
from mhtrack.io.asterix.problems import Problems

N = 24


def _cats() -> set[int]:
    return {int(c) for c in _lib.modules()[1].manifest["CATS"]}


def _plots() -> dict[str, np.ndarray]:
    rng = np.random.default_rng(5)
    return {"time": 43200.0 + np.sort(rng.uniform(0, 60, N)),
            "slant": rng.uniform(1e3, 4e5, N), "bearing": rng.uniform(0, 360, N)}


def _blocks(monkeypatch: pytest.MonkeyPatch) -> tuple[list[bytes], list[float]]:
    """Data blocks of two plots each (small records, many of them)."""
    import mhtrack.io.asterix.encode as enc

    monkeypatch.setattr(enc, "MAX_RECORDS", 2)
    p = _plots()
    got = list(encode_blocks(plot_messages(p["time"], np.full(N, 513), p["slant"],
                                           p["bearing"], {})))
    return [b for _, _, b in got], [t for t, _, _ in got]


def _framed(blocks: list[bytes], times: list[float]) -> dict[str, tuple[str, bytes]]:
    """Every framing: name → (expected kind, file octets)."""
    eth = wrap.udp_frames(blocks, 513)
    v6 = []
    for f in eth:  # IPv6 with a hop-by-hop extension header (8 octets) before UDP
        udp = f[34:]
        v6.append(f[:12] + b"\x86\xdd" + struct.pack("!IHBB", 6 << 28, 8 + len(udp), 0, 64)
                  + bytes(32) + bytes([17, 0]) + bytes(6) + udp)
    snap = [f[:12] + struct.pack("!H", 8 + len(f) - 14) + b"\xaa\xaa\x03\0\0\0\x08\x00"
            + f[14:] for f in eth]
    oradis_udp = wrap.udp_frames([wrap.oradis([b], [t]) for b, t in zip(blocks, times,
                                                                      strict=True)], 513)
    return {
        "raw": ("raw", b"".join(blocks)),
        "gps": ("gps", wrap.gps(blocks, times, b"GPS recorder")),
        "final": ("final", wrap.final(blocks, times)),
        "oradis": ("oradis", wrap.oradis(blocks, times)),
        "pcap": ("pcap", wrap.pcap(eth, times)),
        "pcap-ns-be": ("pcap", wrap.pcap(eth, times, order=">", nano=True)),
        "pcapng-ns": ("pcapng", wrap.pcapng(eth, times, tsresol=9)),
        "pcapng-be-2^-20": ("pcapng", wrap.pcapng(eth, times, order=">", tsresol=0x94)),
        "vlan": ("pcap", wrap.pcap([wrap.vlan(f, [(0x8100, 5)]) for f in eth], times)),
        "qinq": ("pcap", wrap.pcap([wrap.vlan(f, [(0x88A8, 3), (0x8100, 5)]) for f in eth],
                                   times)),
        "sll": ("pcap", wrap.pcap([wrap.sll(f) for f in eth], times, link=113)),
        "sll2": ("pcapng", wrap.pcapng([wrap.sll2(f) for f in eth], times, link=276)),
        "llc": ("pcap", wrap.pcap([wrap.llc_frame(b, 513) for b in blocks], times)),
        "snap": ("pcap", wrap.pcap(snap, times)),
        "ipv6-ext": ("pcap", wrap.pcap(v6, times)),
        "oradis-udp": ("pcap", wrap.pcap(oradis_udp, times)),
    }


def _decode(payloads: list[bytes]) -> np.ndarray:
    """``(time, slant, bearing)`` of every CAT048 plot, by libasterix."""
    base = _lib.modules()[0]
    rows = []
    for octets in payloads:
        pos = 0
        while pos < len(octets):
            length = int.from_bytes(octets[pos + 1:pos + 3], "big")
            recs = _lib.cat048().cv_uap.parse(base.Bits.from_bytes(octets[pos + 3:pos +
                                                                          length]))
            rows += [plot_row(r, pos, Problems()) for r in recs]
            pos += length
    return np.array([(r[0], r[4], r[5]) for r in rows])


def test_every_framing_round_trips(monkeypatch: pytest.MonkeyPatch) -> None:
    blocks, times = _blocks(monkeypatch)
    p, L = _plots(), lsb()
    cats = _cats()
    for name, (kind, data) in _framed(blocks, times).items():
        assert recognise(data, name, cats) == kind, name
        problems = Problems()
        got = list(units(data, kind, name, cats, problems))
        assert not problems.counts, (name, problems.counts)
        assert [u[2] for u in got] == blocks, name
        for offset, _, octets in got:  # offsets point at the payload in the file
            assert data[offset:offset + len(octets)] == octets, name
        t = np.array([u[1] for u in got], dtype=float)
        if kind in ("raw", "oradis"):
            assert np.isnan(t).all(), name
        else:
            step = {"gps": 1 / 128, "final": 0.01}.get(kind, 1e-6)
            assert np.abs(t - np.array(times)).max() <= step / 2 + 1e-9, name
        plots = _decode([u[2] for u in got])
        assert np.abs(plots[:, 0] - p["time"]).max() <= L["tod_s"], name
        assert np.abs(plots[:, 1] - p["slant"]).max() <= L["rho_nm"] * 1852.0, name
        ang = (plots[:, 2] - p["bearing"] + 180.0) % 360.0 - 180.0
        assert np.abs(ang).max() <= L["theta_deg"], name


def test_pyasteryx_reads_the_unwrapped_blocks(monkeypatch: pytest.MonkeyPatch,
                                              tmp_path: Path) -> None:
    pyasteryx = pytest.importorskip("pyasteryx", reason="pyasteryx (extra [reference]) "
                                    "not installed")
    blocks, times = _blocks(monkeypatch)
    framed = _framed(blocks, times)
    (tmp_path / "v.pcap").write_bytes(framed["vlan"][1])
    ref = [m.items for m in pyasteryx.Decoder().decode_pcap(str(tmp_path / "v.pcap"))]
    p = _plots()
    assert len(ref) == N  # its own pcap and VLAN reader sees the same datagrams
    cats = _cats()
    for name, (kind, data) in framed.items():
        got = [u[2] for u in units(data, kind, name, cats, Problems())]
        msgs = [m.items for octets in got for m in pyasteryx.Decoder().decode(octets)]
        assert msgs == ref, name
    rho = np.array([r["I048/040"]["RHO"] for r in ref]) * 1852.0
    assert np.abs(rho - p["slant"]).max() <= lsb()["rho_nm"] * 1852.0


def test_the_real_capture_as_pyasteryx_reads_it(conformance_pcap: Path) -> None:
    """Every UDP payload of the real capture, as pyasteryx's own pcap reader gives them,
    each at its offset in the file, with the packet's capture time."""
    pyasteryx = pytest.importorskip("pyasteryx", reason="pyasteryx (extra [reference]) "
                                    "not installed")
    from pyasteryx.io import iter_pcap_payloads

    data = conformance_pcap.read_bytes()
    problems = Problems()
    got = list(units(data, "pcap", "c", _cats(), problems))
    assert [u[2] for u in got] == list(iter_pcap_payloads(conformance_pcap))
    assert len(got) == 100 and not problems.counts and pyasteryx
    for offset, when, octets in got:
        assert data[offset:offset + len(octets)] == octets
        head = offset - 42  # Ethernet 14 + IPv4 20 + UDP 8 octets before the payload
        sec, usec = struct.unpack_from("<II", data, head - 16)
        assert when == sec + usec * 1e-6


def test_no_recording_refused_at_byte_0() -> None:
    with pytest.raises(InputError, match="byte 0: not an ASTERIX recording"):
        recognise(b"hello world, not a recording", "x.bin", _cats())
    with pytest.raises(InputError, match="byte 0"):
        recognise(b"", "empty.bin", _cats())


def _flip(data: bytes, at: int, bit: int) -> bytes:
    return data[:at] + bytes([data[at] ^ (1 << bit)]) + data[at + 1:]


def _record_spans(kind: str, data: bytes, blocks: list[bytes]) -> list[tuple[int, int]]:
    """``[start, next start)`` of the framing record of each block in the undamaged file
    (the file's headers belong to the first), walked here by the record lengths."""
    starts, pos = [], 0
    if kind == "pcap":
        pos, e = 24, "<" if data[0] == 0xD4 else ">"
        while pos < len(data):
            starts.append(pos)
            pos += 16 + struct.unpack_from(e + "I", data, pos + 8)[0]
    elif kind == "pcapng":
        e = "<" if data[8] == 0x4D else ">"
        while pos < len(data):
            if struct.unpack_from(e + "I", data, pos)[0] == 6:
                starts.append(pos)
            pos += struct.unpack_from(e + "I", data, pos + 4)[0]
    else:
        for b in blocks:
            at = data.index(b, pos)
            starts.append(at - {"final": 8, "oradis": 6}.get(kind, 0))
            pos = at + len(b)
    assert len(starts) == len(blocks)
    starts[0] = 0
    return list(zip(starts, [*starts[1:], len(data)], strict=True))


def _header_end(kind: str, data: bytes) -> int:
    """Where a capture's first packet record starts (its headers before it)."""
    if kind == "pcap":
        return 24
    if kind == "pcapng":
        e = "<" if data[8] == 0x4D else ">"
        shb = struct.unpack_from(e + "I", data, 4)[0]
        return shb + struct.unpack_from(e + "I", data, shb + 4)[0]
    return 2200 if kind == "gps" else 0


KINDS = ("raw", "gps", "final", "oradis", "pcap", "pcapng-ns", "llc", "sll2")


@settings(max_examples=150, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(kind=st.sampled_from(KINDS), where=st.floats(0.0, 0.999), bit=st.integers(0, 7),
       how=st.sampled_from(("flip", "truncate", "garbage")))
def test_damage_is_skipped_per_record(monkeypatch: pytest.MonkeyPatch, kind: str,
                                      where: float, bit: int, how: str) -> None:
    blocks, times = _blocks(monkeypatch)
    expected, data = _framed(blocks, times)[kind]
    spans = _record_spans(expected, data, blocks)
    at = int(where * len(data))
    if how == "flip":
        bad = _flip(data, at, bit)
    elif how == "truncate":
        bad = data[:at]
    else:
        bad = data[:at] + bytes([0xFF, 0x00, 0x13, 0x37, bit]) + data[at:]
    cats = _cats()
    try:
        found = recognise(bad, kind, cats)
    except InputError:  # the documented refusal: the file's headers (a GPS file's 2 200
        # octets) or, cut short, its first record no longer make a recording
        assert at < _header_end(expected, data) or (how == "truncate" and at < spans[1][0])
        return
    problems = Problems()
    try:
        got = [u[2] for u in units(bad, found, kind, cats, problems)]
    except InputError:  # the documented refusal: a capture's link type not read
        assert at < _header_end(expected, data)
        return
    if at < _header_end(expected, data) or found != expected:
        # damage to the headers (magic, link type, interface description) or to the first
        # records, which identify the framing: only the absence of a traceback is promised
        assert at < max(_header_end(expected, data), spans[min(2, len(spans) - 1)][0])
        return
    shift = 5 if how == "garbage" else 0
    hit = [i for i, (s, e) in enumerate(spans) if s <= at < e]
    first_bad = hit[0] if hit else next((i for i, (s, _) in enumerate(spans) if s >= at),
                                        len(spans))
    before = blocks[:first_bad]
    assert got[:len(before)] == before  # every record before the damage, in order
    if how != "truncate" and kind != "raw":  # and every record from the second after it
        # (a raw stream has no framing of its own: a damaged length that still fits takes
        # the blocks it covers with it; the decoder finds them undecodable)
        after = [b for (s, _), b in zip(spans, blocks, strict=True)
                 if s > at and spans.index((s, _)) >= first_bad + 2]
        assert all(b in got for b in after), (problems.counts, shift)
