"""The re-order buffer: a hand-worked stream, a plain reference implementation of its
rule (a list sorted at every step), and the properties the rule promises."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.io.reorder import ReorderBuffer


def _run(times: list[float], window: float, cuts: list[int] | None = None
         ) -> tuple[list[int], ReorderBuffer]:
    """Push ``times`` in batches cut at ``cuts``; the released arrival numbers."""
    buf = ReorderBuffer(window)
    t = np.asarray(times, float)
    bounds = [0, *sorted(set(c for c in (cuts or []) if 0 < c < t.size)), t.size]
    out: list[int] = []
    for a, b in itertools.pairwise(bounds):
        got = buf.push({"time": t[a:b], "tag": np.arange(a, b)})
        if got:
            assert got["seq"].tolist() == got["tag"].tolist()  # columns travel together
            out += got["seq"].tolist()
    out += buf.flush().get("seq", np.zeros(0, int)).tolist()
    return out, buf


def _plain(times: list[float], window: float) -> tuple[list[int], list[int], list[int]]:
    """The rule, written plainly, after ``times`` (no flush): arrival numbers released,
    still held (in time order), dropped."""
    held: list[tuple[float, int]] = []
    out, dropped = [], []
    latest = released = -np.inf
    for i, t in enumerate(times):
        if t < released:
            dropped.append(i)
            continue
        latest = max(latest, t)
        held.append((t, i))
        for h in sorted(h for h in held if latest - h[0] > window):
            out.append(h[1])
            held.remove(h)
            released = h[0]
    return out, [i for _, i in sorted(held)], dropped


def _reference(times: list[float], window: float) -> tuple[list[int], list[int]]:
    """The plain rule with the flush at the end: (released arrival numbers, dropped ones)."""
    out, held, dropped = _plain(times, window)
    return out + held, dropped


def test_hand_worked() -> None:
    # window 2 s: 5 releases 0 and 1; 2 is re-ordered (and released at once: 5 − 2 > 2);
    # 0.5 is before the released 2 (late by 5 − 0.5); 10 releases 5; 3 is before 5 (late
    # by 7); the end releases 10.
    out, buf = _run([0, 1, 5, 2, 0.5, 10, 3], 2.0)
    assert out == [0, 1, 3, 2, 5]
    assert (buf.late.n, buf.late.max_late_s, buf.late.first_late_s) == (2, 7.0, 4.5)
    assert buf.late.first == {"time": 0.5, "tag": 4}
    assert buf.reordered == 1
    assert buf.late.line("rec.pcap", "byte 7").startswith(
        "rec.pcap: 2 plots dropped, late by up to 7 s")


def test_one_plot_late_by_40_s() -> None:
    times = [float(k) for k in range(100)]
    times.insert(80, 39.0)  # sent at 39 s, arrives after the plot of 79 s
    out, buf = _run(times, 2.0)
    assert (buf.late.n, buf.late.max_late_s) == (1, 40.0)
    assert buf.late.line("x", "line 82") == (
        "x: 1 plot dropped, late by 40 s (after later plots had gone to the tracker, "
        "beyond the reorder window; first at line 82)")
    assert out == [i for i in range(101) if i != 80]


def test_ties_keep_arrival_order() -> None:
    out, _ = _run([1.0, 3.0, 1.0, 1.0, 2.0, 3.0, 1.0], 5.0)
    assert out == [0, 2, 3, 6, 4, 1, 5]


times_st = st.lists(st.integers(0, 40).map(lambda k: k / 4), min_size=0, max_size=60)


@settings(max_examples=200, deadline=None)
@given(times_st, st.sampled_from([0.0, 0.25, 1.0, 2.0, 5.0]),
       st.lists(st.integers(0, 60), max_size=6))
def test_matches_the_plain_rule_in_any_batches(times, window, cuts) -> None:
    out, buf = _run(times, window, cuts)
    ref, dropped = _reference(times, window)
    assert out == ref
    assert buf.late.n == len(dropped)


@settings(max_examples=200, deadline=None)
@given(times_st, st.sampled_from([0.0, 0.5, 2.0]))
def test_properties(times, window) -> None:
    out, buf = _run(times, window)
    t = np.asarray(times, float)
    # time order, ties by arrival
    assert out == sorted(out, key=lambda i: (times[i], i))
    # a plot within the window of every earlier one is never dropped (read_timed_plots'
    # acceptance rule)
    before = np.maximum.accumulate(np.concatenate(([-np.inf], t)))[:-1]
    assert set(np.flatnonzero(t >= before - window).tolist()) <= set(out)
    assert len(out) + buf.late.n == len(times)
    if not buf.late.n and t.size and np.all(t >= before - window):
        assert out == np.argsort(t, kind="stable").tolist()


@settings(max_examples=200, deadline=None)
@given(times_st, st.sampled_from([0.0, 0.25, 1.0]), st.lists(st.integers(0, 60), max_size=8))
def test_holds_what_the_rule_holds_and_no_late_plot(times, window, cuts) -> None:
    """After every batch the buffer holds exactly the plots the plain rule still holds
    (by arrival number, in leaving order), and keeps no column of a dropped plot."""
    buf = ReorderBuffer(window)
    t = np.asarray(times, float)
    bounds = [0, *sorted(set(c for c in cuts if 0 < c < t.size)), t.size]
    for a, b in itertools.pairwise(bounds):
        buf.push({"time": t[a:b], "tag": np.arange(a, b)})
        held = buf.held()
        _, want, _ = _plain(times[:b], window)  # still held, in (time, arrival) order
        assert (held["tag"].tolist() if held is not None else []) == want
        assert buf._held_seq.size == len(want)

