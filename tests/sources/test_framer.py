"""The incremental framer gives exactly :func:`mhtrack.frames.make_frames`' frames (the
independent reference: the whole stream cut at once), whatever the batches, and gives
each frame out without waiting for the end of the stream."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.frames import make_frames
from mhtrack.sources.framer import Framer


def _frames(t: np.ndarray, s: np.ndarray, lengths: dict[int, float] | float,
            cuts: list[int]) -> list[tuple[int, int, float, list[int], int]]:
    """(index, sensor, time, input positions, batches pushed when it came out)."""
    fr = Framer(lengths)
    bounds = [0, *sorted(set(c for c in cuts if 0 < c < t.size)), t.size]
    out = []
    for k, (a, b) in enumerate(itertools.pairwise(bounds)):
        for f in fr.push({"time": t[a:b], "sensor": s[a:b], "pos": np.arange(a, b)}):
            out.append((f.index, f.sensor, f.time, f.cols["pos"].tolist(), k + 1))
    for f in fr.flush():
        out.append((f.index, f.sensor, f.time, f.cols["pos"].tolist(), -1))
    return out


def _check_against_make_frames(t, s, lengths, cuts) -> list:
    got = _frames(t, s, lengths, cuts)
    frame, order = make_frames(t, s, lengths)
    want = [order[frame[order] == k].tolist() for k in range(int(frame.max()) + 1)] \
        if t.size else []
    assert [g[3] for g in got] == want
    assert [g[0] for g in got] == list(range(len(want)))
    for g in got:
        assert set(s[g[3]].tolist()) == {g[1]} and g[2] == t[g[3]].max()
    return got


def test_hand_worked_two_radars() -> None:
    # test_frames' hand-worked case, in time order: radar 1 {0.0, 0.1, 0.5} {1.2},
    # radar 2 {0.3, 0.9} {2.5}; ordered by end 0.5, 0.9, 1.2, 2.5.
    t = np.array([0.0, 0.1, 0.3, 0.5, 0.9, 1.2, 2.5])
    s = np.array([1, 1, 2, 1, 2, 1, 2])
    got = _check_against_make_frames(t, s, 1.0, [1, 2, 3, 4, 5, 6])
    # 1.2 (batch 6) closes radar 1's {0.0, 0.1, 0.5}; radar 2's open frame already ends
    # at 0.9 > 0.5, so it goes at once. 2.5 (batch 7) closes {0.3, 0.9} and, being more
    # than 1 s after 1.2, {1.2}: both go. {2.5} waits for the end.
    assert [g[4] for g in got] == [6, 7, 7, -1]


@st.composite
def streams(draw):
    n = draw(st.integers(0, 80))
    steps = draw(st.lists(st.sampled_from([0.0, 0.0, 0.125, 0.25, 0.5, 1.0, 3.0]),
                          min_size=n, max_size=n))
    t = np.cumsum(np.asarray(steps, float))
    s = np.asarray(draw(st.lists(st.integers(1, 4), min_size=n, max_size=n)), np.int64)
    lengths = {k: draw(st.sampled_from([0.25, 0.5, 1.0, 1.5, 2.0])) for k in range(1, 5)}
    cuts = draw(st.lists(st.integers(0, max(n, 1)), max_size=10))
    return t, s, lengths, cuts


@settings(max_examples=300, deadline=None)
@given(streams())
def test_same_frames_as_make_frames(stream) -> None:
    _check_against_make_frames(*stream)


@settings(max_examples=100, deadline=None)
@given(st.lists(st.floats(0, 1e4, allow_nan=False), min_size=1, max_size=60),
       st.lists(st.integers(0, 2), min_size=60, max_size=60), st.floats(0.01, 50))
def test_same_frames_on_unrounded_times(times, sensors, length) -> None:
    t = np.sort(np.asarray(times))
    s = np.asarray(sensors[:t.size], np.int64)
    _check_against_make_frames(t, s, length, list(range(0, t.size, 7)))


def test_frames_come_out_while_the_stream_runs() -> None:
    # three radars, one plot each every 0.1 s for 100 s, one plot per batch: every frame
    # but the last three comes out before the end, at most one frame length + a step late
    t = np.repeat(np.arange(1000) * 0.1, 3)
    s = np.tile([1, 2, 3], 1000)
    got = _check_against_make_frames(t, s, {1: 0.5, 2: 1.0, 3: 1.5},
                                     list(range(3, t.size, 3)))
    assert sum(g[4] == -1 for g in got) == 3
    for g in got:
        if g[4] != -1:
            now = t[3 * g[4] - 1]  # stream time when it came out
            assert now - g[2] <= 1.5 + 0.1 + 1e-9


def _brute_sectors(t, s, sec, lengths) -> list[list[int]]:
    """Frames by the rule, plot by plot: a sensor's frame takes its plots while they are
    in the frame's first plot's sector and within its length; ordered by (end, sensor)."""
    open_: dict[int, list[int]] = {}
    done = []
    for i in range(t.size):
        k = int(s[i])
        f = open_.get(k)
        if f is not None and (sec[i] != sec[f[0]] or t[i] - t[f[0]] > lengths[k]):
            done.append(f)
            f = None
        if f is None:
            f = open_[k] = []
        f.append(i)
    done += list(open_.values())
    done.sort(key=lambda f: (t[f[-1]], int(s[f[0]]), f[0]))
    return done


@settings(max_examples=200, deadline=None)
@given(streams(), st.data())
def test_sector_cuts_as_the_rule_says(stream, data) -> None:
    t, s, lengths, cuts = stream
    sec = np.zeros(t.size, np.int64)  # each sensor's sector count never goes back
    for k in range(1, 5):
        mine = np.flatnonzero(s == k)
        steps = data.draw(st.lists(st.sampled_from([0, 0, 1]), min_size=mine.size,
                                   max_size=mine.size))
        sec[mine] = np.cumsum(steps)
    fr = Framer(lengths)
    bounds = [0, *sorted(set(c for c in cuts if 0 < c < t.size)), t.size]
    got = []
    for a, b in itertools.pairwise(bounds):
        got += [f.cols["pos"].tolist() for f in fr.push(
            {"time": t[a:b], "sensor": s[a:b], "sector": sec[a:b], "pos": np.arange(a, b)})]
    got += [f.cols["pos"].tolist() for f in fr.flush()]
    assert got == _brute_sectors(t, s, sec, lengths)


@settings(max_examples=150, deadline=None)
@given(streams(), st.integers(0, 80))
def test_pending_plots_continue_in_a_fresh_framer(stream, stop) -> None:
    """Stopped after any batch, the plots a framer holds (:meth:`Framer.pending`) pushed
    into a fresh framer (numbered on) with the batches after the stop give the frames of
    the framer never stopped: what a resumed live run relies on."""
    t, s, lengths, cuts = stream
    bounds = [0, *sorted(set(c for c in cuts if 0 < c < t.size)), t.size]
    pieces = list(itertools.pairwise(bounds))
    stop = min(stop, len(pieces))

    def batch(a: int, b: int) -> dict[str, np.ndarray]:
        return {"time": t[a:b], "sensor": s[a:b], "pos": np.arange(a, b)}

    first, got = Framer(lengths), []
    for a, b in pieces[:stop]:
        got += [f.cols["pos"].tolist() for f in first.push(batch(a, b))]
    second = Framer(lengths)
    second.n_frames = first.n_frames
    held = first.pending()
    if held is not None:
        got += [f.cols["pos"].tolist() for f in second.push(held)]
    for a, b in pieces[stop:]:
        got += [f.cols["pos"].tolist() for f in second.push(batch(a, b))]
    got += [f.cols["pos"].tolist() for f in second.flush()]
    want = [g[3] for g in _frames(t, s, lengths, cuts)]
    assert got == want


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 3), st.integers(1, 3)), min_size=1, max_size=80),
       st.integers(1, 30), st.integers(1, 10))
def test_a_ring_of_rows_knows_the_last_rows_as_the_whole_map(plots, keep, batch) -> None:
    """``TimedStream(keep_rows=K)`` (a live stream: memory flat) gives the same frames,
    and for the last ``K`` rows out the same file rows as the stream keeping them all;
    older rows are ``-1`` (forgotten), never another plot's row."""
    from mhtrack.sources.base import SourceStats
    from mhtrack.sources.timed import TimedStream

    rng = np.random.default_rng(len(plots))
    t = np.cumsum([dt for dt, _ in plots])
    cols = {"time": t, "sensor": np.array([s for _, s in plots]), "x": t, "y": t,
            "file_row": rng.permutation(t.size) + 100}

    def run(keep_rows):
        ts = TimedStream("s", SourceStats(), 1.0, 0.5, str, keep_rows=keep_rows)
        out = []
        for a in range(0, t.size, batch):
            out += list(ts.push({k: v[a:a + batch] for k, v in cols.items()}))
        return out + list(ts.finish()), ts

    whole, full = run(None)
    ring, kept = run(keep)
    assert [f.rows.tolist() for f in ring] == [f.rows.tolist() for f in whole]
    rows = np.arange(-2, t.size)  # (-1: no plot)
    want = full.file_rows(rows)
    want[rows < t.size - keep] = -1
    assert kept.file_rows(rows).tolist() == want.tolist()
