"""Reports that are not plots (notplots.py) and data blocks received twice
(duplicates.py): the I048/020 bit rule against libasterix, hand-worked masks, the real
dual-LAN capture (126 reports, 63 distinct), every block doubled, and a brute-force
reference of the duplicate rule."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import mhtrack.io.asterix._lib as _lib
from mhtrack.io.asterix import wrap
from mhtrack.io.asterix.container import blocks
from mhtrack.io.asterix.decode import plot_row
from mhtrack.io.asterix.duplicates import DuplicateFilter
from mhtrack.io.asterix.encode import encode_blocks, plot_messages
from mhtrack.io.asterix.framings import units
from mhtrack.io.asterix.notplots import (
    REASONS,
    flags048,
    flags048_octets,
    plot_type048,
    real_plots,
    reason,
)
from mhtrack.io.asterix.problems import Problems


def _parse048(raw: bytes) -> list:
    base = _lib.modules()[0]
    got = _lib.cat048().cv_uap.parse(base.Bits.from_bytes(raw))
    assert not isinstance(got, ValueError)
    return got


def test_i048_020_bits_agree_with_libasterix() -> None:
    """Every first octet of I048/020, with and without its first extension."""
    for first in range(256):
        for second in (0x00, 0x80, 0x7E, 0xFE):
            octets = bytes([first, second]) if first & 1 else bytes([first])
            rec = _parse048(bytes([0b00100000]) + octets)[0]  # FSPEC: FRN 3 = I048/020
            assert flags048(rec) == flags048_octets(octets), (first, second)


def test_real_plots_hand_worked() -> None:
    typ = np.array([0, 1, 2, 3, 4, 5, 6, 7, -1, 3, 0, 2])
    sim = np.array([0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1])
    rab = np.array([0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0])
    tst = np.array([0, 1, 1, 0, 0, 0, 0, 0, -1, 0, 0, 0])
    keep, counts = real_plots(typ, sim, rab, tst)
    assert keep.tolist() == [False, False, False, True, True, True, True, True, True,
                             False, False, False]
    # each report under its first reason: no detection, then test, field monitor, SIM
    # (report 9 is a field monitor before it is simulated, report 10 no detection)
    assert counts == {"no_detection": 2, "track": 0, "test": 2, "field_monitor": 1,
                      "simulated": 1}
    assert tuple(counts) == REASONS
    assert plot_type048(np.array([-1, 0, 1, 2, 3, 4, 5, 6, 7])).tolist() == \
        [0, 0, 1, 2, 3, 4, 4, 3, 3]


def _plots_of(data: bytes, kind: str, dedupe: DuplicateFilter | None
              ) -> list[tuple]:
    problems, rows = Problems(), []
    cats = {int(c) for c in _lib.modules()[1].manifest["CATS"]}
    for offset, time, payload in units(data, kind, "t", cats, problems):
        for at, cat, raw in blocks(payload, offset, problems):
            block = payload[at - offset:at - offset + 3 + len(raw)]
            if dedupe is not None and not dedupe.keep(block, time):
                continue
            if cat == 48:
                rows += [r for r in (plot_row(x, at, problems) for x in _parse048(raw))
                         if r is not None]
    return rows


flag = st.integers(-1, 1)


@given(st.lists(st.tuples(st.integers(-1, 7), flag, flag, flag, flag), max_size=40))
def test_real_plots_is_reason_row_by_row(rows: list[tuple[int, ...]]) -> None:
    """The columns' mask and counts are those of :func:`reason` asked report by report
    (the former implementation of ``real_plots``)."""
    typ, sim, rab, tst, track = (np.array(c, np.int64).reshape(-1)
                                 for c in zip(*rows, strict=True)) if rows else \
        (np.zeros(0, np.int64),) * 5
    keep, counts = real_plots(typ, sim, rab, tst, track=track)
    why = [reason(*r) for r in zip(typ.tolist(), sim.tolist(), rab.tolist(), tst.tolist(),
                                   track.tolist(), strict=True)]
    assert keep.tolist() == [w is None for w in why]
    assert counts == {name: why.count(name) for name in REASONS}


def test_the_dual_lan_capture_has_63_distinct_plots(conformance_pcap: Path) -> None:
    data = conformance_pcap.read_bytes()
    every = _plots_of(data, "pcap", None)
    dedupe = DuplicateFilter()
    kept = _plots_of(data, "pcap", dedupe)
    assert len(every) == 126 and len(kept) == 63
    assert sorted(set(every)) == sorted(kept)  # each distinct report once
    assert dedupe.dropped == dedupe.count // 2  # every block arrived on both LANs


def test_every_block_doubled_gives_the_single_copy() -> None:
    n = 40
    msgs = plot_messages(100.0 + np.arange(n) * 0.25, np.full(n, 513),
                         np.linspace(1e4, 2e5, n), np.arange(n) * 9.0, {})
    got = list(encode_blocks(msgs))
    blocks_, times = [b for _, _, b in got], [t for t, _, _ in got]
    single = wrap.pcap(wrap.udp_frames(blocks_, 513), times)
    frames, ftimes = [], []
    for f, t in zip(wrap.udp_frames(blocks_, 513), times, strict=True):
        frames += [f, f[:6] + bytes([2, 0, 0, 0, 0, 9]) + f[12:]]  # LAN B: another MAC
        ftimes += [t, t + 0.0007]
    doubled = wrap.pcap(frames, ftimes)
    dedupe = DuplicateFilter()
    assert _plots_of(doubled, "pcap", dedupe) == _plots_of(single, "pcap", None)
    assert dedupe.dropped == len(blocks_)
    assert len(_plots_of(doubled, "pcap", None)) == 2 * n


def test_a_block_repeated_after_the_window_is_kept() -> None:
    f = DuplicateFilter(window=0.5)
    assert f.keep(b"\x30\x00\x04\x01", 10.0)
    assert not f.keep(b"\x30\x00\x04\x01", 10.4)
    assert f.keep(b"\x30\x00\x04\x01", 10.6)  # 0.6 s after the first copy
    g = DuplicateFilter(span=2)  # no capture times: the last 2 blocks
    assert [g.keep(b, None) for b in (b"a", b"b", b"a", b"c", b"d", b"a")] == \
        [True, True, False, True, True, True]
    with pytest.raises(ValueError, match="window"):
        DuplicateFilter(window=-1.0)


def _brute(seq: list[tuple[int, float]], window: float) -> list[bool]:
    """Drop a block when an identical block kept before it is within ``window`` s."""
    kept: list[tuple[int, float]] = []
    out = []
    for block, t in seq:
        dup = any(b == block and abs(t - tk) <= window for b, tk in kept)
        out.append(not dup)
        if not dup:
            kept.append((block, t))
    return out


@given(st.lists(st.tuples(st.integers(0, 5), st.floats(0.0, 0.4)), max_size=60),
       st.floats(0.0, 1.0))
def test_the_filter_matches_the_brute_force_rule(steps: list[tuple[int, float]],
                                                 window: float) -> None:
    t, seq = 0.0, []
    for block, dt in steps:  # capture times in order
        t += dt
        seq.append((block, t))
    f = DuplicateFilter(window=window, span=64)
    got = [f.keep(bytes([48, 0, 4, b]), tt) for b, tt in seq]
    assert got == _brute(seq, window)
    assert f.dropped == got.count(False)


@given(st.lists(st.integers(0, 200), max_size=300), st.integers(1, 20))
def test_memory_is_bounded_by_the_span(blocks_: list[int], span: int) -> None:
    f = DuplicateFilter(window=1e9, span=span)
    for i, b in enumerate(blocks_):
        f.keep(bytes([48, 0, 4, b]), float(i))
        assert len(f.seen) <= span


@given(st.lists(st.integers(0, 30), max_size=120), st.integers(0, 120),
       st.integers(1, 16), st.booleans())
def test_a_restored_filter_decides_as_the_filter_never_stopped(
        blocks_: list[int], cut: int, span: int, with_times: bool) -> None:
    """A stream filter's :meth:`recent` digests, restored into a fresh filter (a live run
    resumed from its checkpoint), make the same keep/drop decisions on the rest of the
    stream as the filter that saw it all — a copy late across the restart is a copy."""
    from mhtrack.io.asterix.duplicates import stream_filter

    seq = [bytes([48, 0, 4, b]) for b in blocks_]
    cut = min(cut, len(seq))
    whole = stream_filter(span)
    want = [whole.keep(b, float(i) if with_times else None) for i, b in enumerate(seq)]
    first = stream_filter(span)
    got = [first.keep(b, float(i) if with_times else None) for i, b in enumerate(seq[:cut])]
    second = stream_filter(span)
    second.restore(first.recent())
    got += [second.keep(b, float(i) if with_times else None)
            for i, b in enumerate(seq[cut:], cut)]
    assert got == want
    assert len(second.seen) <= span


def test_restore_refuses_what_is_no_list_of_digests() -> None:
    from mhtrack.io.asterix.duplicates import stream_filter

    good = stream_filter()
    good.keep(bytes([48, 0, 4, 1]))
    good.keep(bytes([48, 0, 4, 2]))
    text = good.recent()
    assert len(text) == 80 and text[32:40] == "00000001" and text[72:80] == "00000000"
    swapped = text[40:] + text[:40]  # the newer block first: ages must fall
    for bad, match in ((3, "hex string"), (text[:-1], "multiple of 40"),
                       ("zz" * 20, "not a hex"), (text[:40] * 2, "twice"),
                       ("00" * 20 * 5, "at most"), (swapped, "ages must fall"),
                       (text[:32] + "ffffffff", "ages must fall")):
        f = stream_filter(span=4)
        with pytest.raises(ValueError, match=match):
            f.restore(bad)
