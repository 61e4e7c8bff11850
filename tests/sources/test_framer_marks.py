"""Sweep marks among the plots (:mod:`mhtrack.sources.framer`, ``mark`` rows): on random
streams of two or three radars whose crossings come in time order with their plots, the
marks change *when* frames go out, never which frames, nor their order (``release``
``"time"``): the same frames as the sector column alone gives, each out no later."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.sources.framer import Framer


@st.composite
def streams(draw):
    n_radars = draw(st.integers(1, 3))
    rows = []  # (time, sensor, sector, mark)
    for s in range(1, n_radars + 1):
        crossings = sorted(draw(st.lists(st.integers(0, 400), min_size=0, max_size=12,
                                         unique=True)))
        plots = draw(st.lists(st.integers(0, 400), min_size=1, max_size=30))
        for c in crossings:  # the radar's count of marks with this one
            rows.append((c / 8, s, 1 + crossings.index(c), True))
        for p in plots:  # the count of marks at or before it (a mark first at a tie)
            rows.append((p / 8, s, int(np.searchsorted(crossings, p, side="right")), False))
    rows.sort(key=lambda r: (r[0], not r[3]))
    cuts = sorted(draw(st.lists(st.integers(1, max(1, len(rows) - 1)), max_size=6)))
    lengths = {s: draw(st.sampled_from([0.5, 1.0, 3.0])) for s in range(1, n_radars + 1)}
    return rows, cuts, lengths


def _run(rows, cuts, lengths, marks: bool):
    use = [r for r in rows if marks or not r[3]]
    pos = np.array([rows.index(r) for r in use])  # place in the full stream
    cols = {"time": np.array([r[0] for r in use]), "sensor": np.array([r[1] for r in use]),
            "sector": np.array([r[2] for r in use]), "mark": np.array([r[3] for r in use]),
            "id": np.arange(len(use))}
    if not marks:
        del cols["mark"]
    fr = Framer(lengths)
    out = []
    edges = [0, *cuts, len(rows)]
    for k, (a, b) in enumerate(pairwise(edges)):
        sel = (pos >= a) & (pos < b)
        for f in fr.push({c: v[sel] for c, v in cols.items()}):
            out.append((f.sensor, f.time, [int(pos[i]) for i in f.cols["id"]], k))
    for f in fr.flush():
        out.append((f.sensor, f.time, [int(pos[i]) for i in f.cols["id"]], len(edges)))
    return out


@settings(max_examples=150, deadline=None)
@given(streams())
def test_marks_change_when_not_which(stream) -> None:
    rows, cuts, lengths = stream
    with_marks = _run(rows, cuts, lengths, True)
    plain = _run(rows, cuts, lengths, False)
    assert [f[:3] for f in with_marks] == [f[:3] for f in plain]
    assert all(a[3] <= b[3] for a, b in zip(with_marks, plain, strict=True))
    assert all(not rows[i][3] for f in with_marks for i in f[2])  # no mark in a frame


def _frames_out(fr: Framer, batches, k0: int, out: list) -> None:
    """Push ``batches`` (numbered from ``k0``) into ``fr``, then flush; each frame out as
    ``(sensor, time, ids, the closing mark's id or None, batch number)``."""
    for k, b in enumerate(batches, k0):
        for f in fr.push(b):
            out.append((f.sensor, f.time, f.cols["id"].tolist(),
                        None if f.mark is None else int(f.mark["id"]), k))
    for f in fr.flush():
        out.append((f.sensor, f.time, f.cols["id"].tolist(),
                    None if f.mark is None else int(f.mark["id"]), -1))


@settings(max_examples=150, deadline=None)
@given(streams(), st.integers(0, 8), st.sampled_from(["time", "radar"]))
def test_pending_with_marks_continues_in_a_fresh_framer(stream, stop, release) -> None:
    """Stopped after any batch, the rows a framer holds (:meth:`Framer.pending`: the
    plots of open and of closed frames not yet out, and the mark that closed each of the
    latter) pushed into a fresh framer (numbered on, frame times on from the last one
    out), then the batches after the stop: the frames of the framer never stopped, each
    closed by the same mark and out after the same batch — what a resumed live run
    relies on. (Without the marks a closed frame came back open: its mark lost, it waited
    for the next plot or the eighth.)"""
    rows, cuts, lengths = stream
    cols = {"time": np.array([r[0] for r in rows]), "sensor": np.array([r[1] for r in rows]),
            "sector": np.array([r[2] for r in rows]), "mark": np.array([r[3] for r in rows]),
            "id": np.arange(len(rows))}
    edges = [0, *cuts, len(rows)]
    batches = [{c: v[a:b] for c, v in cols.items()} for a, b in pairwise(edges)]
    stop = min(stop, len(batches))
    want: list = []
    _frames_out(Framer(lengths, release=release), batches, 0, want)
    first, got = Framer(lengths, release=release), []
    for k, b in enumerate(batches[:stop]):
        got += [(f.sensor, f.time, f.cols["id"].tolist(),
                 None if f.mark is None else int(f.mark["id"]), k) for f in first.push(b)]
    second = Framer(lengths, release=release)
    second.n_frames, second.last_time = first.n_frames, first.last_time
    held = first.pending()
    if held is not None:  # nothing comes out of the held rows alone
        assert not list(second.push(held))
        assert [k for k, v in held.items()] == list(cols)
        assert np.all(np.diff(held["id"]) > 0)  # in the order pushed
    _frames_out(second, batches[stop:], stop, got)
    assert got == want


def test_a_closed_frame_held_keeps_its_mark() -> None:
    # lengths: radar 1 3 s, radar 2 1 s. Batch 0: radar 2's plot at 0 s, radar 1's at
    # 0.25 s, radar 1's crossing into sector 1 at 0.5 s: it closes radar 1's frame {0.25},
    # which (in track's order) waits for radar 2's open frame {0}, whose end is earlier.
    # Batch 1: radar 2's plot at 1.5 s closes {0} (more than 1 s after it); both go out.
    # Stopped after batch 0 and restored, the held rows must hold the crossing: without
    # it radar 1's frame came back open, went out only at the end (1.5 − 0.25 < 3 s) and
    # without its mark — a frame other than the run never stopped
    b0 = {"time": np.array([0.0, 0.25, 0.5]), "sensor": np.array([2, 1, 1]),
          "sector": np.array([0, 0, 1]), "mark": np.array([False, False, True]),
          "id": np.array([0, 1, 2])}
    b1 = {"time": np.array([1.5]), "sensor": np.array([2]), "sector": np.array([0]),
          "mark": np.array([False]), "id": np.array([3])}
    lengths = {1: 3.0, 2: 1.0}
    want: list = []
    _frames_out(Framer(lengths), [b0, b1], 0, want)
    assert want == [(2, 0.0, [0], None, 1), (1, 0.25, [1], 2, 1), (2, 1.5, [3], None, -1)]
    first = Framer(lengths)
    assert not list(first.push(b0))
    held = first.pending()
    assert held is not None and held["id"].tolist() == [0, 1, 2]  # the crossing too
    second, got = Framer(lengths), []
    assert not list(second.push(held))
    _frames_out(second, [b1], 1, got)
    assert got == want


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 300))
def test_marks_alone_hold_nothing(n: int) -> None:
    """A radar's crossings in batches of their own (``live --sector-frames`` with each
    crossing in its own datagram): nothing of them is kept, however many (each used to
    be kept forever: a long run grew without bound)."""
    fr = Framer(1.0)
    for i in range(n):
        out = list(fr.push({"time": np.array([i / 8]), "sensor": np.array([3]),
                            "sector": np.array([i + 1]), "mark": np.array([True])}))
        assert not out  # a mark is no plot: no frame
    assert fr.batches_held == 0 and fr.pending() is None


@settings(max_examples=100, deadline=None)
@given(st.integers(1, 300))
def test_crossings_of_another_radar_hold_nothing(n: int) -> None:
    # radar 1: a plot every 1/8 s (batch 2i, time i/8); radar 3: a crossing 1/16 s after
    # each (batch 2i + 1). Radar 1's frames (1 s) hold 9 plots, 0/8 … 8/8 s, the next
    # 9/8 …; a frame is closed by the stream's time once a row is more than 1 s after
    # its first plot — the crossing after its 9th plot — and then goes out (its end is
    # earlier than the stream's time, no other frame is open). After n pairs the open
    # frame holds n mod 9 plots, each of its own batch: those batches only are kept
    fr, out = Framer(1.0), 0
    for i in range(n):
        out += len(list(fr.push({"time": np.array([i / 8]), "sensor": np.array([1]),
                                 "sector": np.array([0]), "mark": np.array([False])})))
        out += len(list(fr.push({"time": np.array([i / 8 + 1 / 16]),
                                 "sensor": np.array([3]), "sector": np.array([i + 1]),
                                 "mark": np.array([True])})))
    assert out == n // 9
    assert fr.batches_held == n % 9
    held = fr.pending()
    assert (0 if held is None else len(held["time"])) == n % 9


@settings(max_examples=100, deadline=None)
@given(streams())
def test_only_batches_with_plots_held_are_kept(stream) -> None:
    """After every push, the framer keeps exactly the batches that hold a plot of a
    frame not yet out (:meth:`Framer.pending`'s plot rows; the mark that closed a frame
    is copied, not kept with its batch)."""
    rows, cuts, lengths = stream
    cols = {"time": np.array([r[0] for r in rows]), "sensor": np.array([r[1] for r in rows]),
            "sector": np.array([r[2] for r in rows]), "mark": np.array([r[3] for r in rows])}
    edges = [0, *cuts, len(rows)]
    fr = Framer(lengths)
    for k, (a, b) in enumerate(pairwise(edges)):
        list(fr.push({**{c: v[a:b] for c, v in cols.items()},
                      "batch": np.full(b - a, k)}))
        held = fr.pending()
        plots = set() if held is None else set(held["batch"][~held["mark"]].tolist())
        assert fr.batches_held == len(plots)
