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
