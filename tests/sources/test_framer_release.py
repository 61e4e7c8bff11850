"""``release="radar"`` (:mod:`mhtrack.sources.framer`): the same frames as the time
order (:func:`mhtrack.frames.make_frames`, the independent reference) — the same plots
cut the same way —, each given out no later, and as soon as its own plots are in (its
end before the stream's time); reference times never go back; the default keeps
make_frames' order exactly."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from tests.sources.test_framer import streams  # the same random streams

from mhtrack.frames import make_frames
from mhtrack.sources.framer import Framer


def _run(t, s, lengths, cuts, release):
    """[(sensor, time, positions, batch pushed when it came out)] in output order."""
    fr = Framer(lengths, release=release)
    bounds = [0, *sorted(set(c for c in cuts if 0 < c < t.size)), t.size]
    out = []
    for k, (a, b) in enumerate(itertools.pairwise(bounds)):
        for f in fr.push({"time": t[a:b], "sensor": s[a:b], "pos": np.arange(a, b)}):
            out.append((f.sensor, f.time, f.cols["pos"].tolist(), k + 1, b))
    for f in fr.flush():
        out.append((f.sensor, f.time, f.cols["pos"].tolist(), len(bounds), t.size))
    return out


@settings(max_examples=300, deadline=None)
@given(streams())
def test_radar_release_same_frames_no_later(stream) -> None:
    t, s, lengths, cuts = stream
    by_time = _run(t, s, lengths, cuts, "time")
    by_radar = _run(t, s, lengths, cuts, "radar")
    frame, order = make_frames(t, s, lengths)
    want = [order[frame[order] == k].tolist() for k in range(int(frame.max()) + 1)] \
        if t.size else []
    assert [g[2] for g in by_time] == want  # the default: make_frames' order
    assert sorted(g[2] for g in by_radar) == sorted(want)  # the same frames
    when_time = {tuple(g[2]): g[3] for g in by_time}
    times = [g[1] for g in by_radar]
    assert times == sorted(times)  # reference times never go back
    for sensor, ref, pos, batch, pushed in by_radar:
        end = float(t[pos].max())
        assert ref >= end and set(s[pos].tolist()) == {sensor}
        assert batch <= when_time[tuple(pos)]  # no later than in time order
        if pushed < t.size:  # out before the end: its own plots all in, the stream
            assert end < t[pushed - 1]  # moved past its end


def test_hand_worked_two_radars() -> None:
    # radar 2 (frames of 2 s) has one plot, at 0.0; radar 1 (frames of 0.5 s) at 0.1,
    # 0.2, 0.7, 2.5; one plot per batch. 0.7 (batch 4) closes radar 1's {0.1, 0.2}:
    # by time it waits behind radar 2's open frame (end 0.0 < 0.2), which closes by time
    # at 2.5 (batch 5; 2.5 − 0.0 > 2), then {0.0}, {0.1, 0.2}, {0.7} go in end order.
    # By radar {0.1, 0.2} goes at batch 4; {0.0} at batch 5 with the reference time
    # 0.2 (times never go back; its plot keeps 0.0), then {0.7}.
    t = np.array([0.0, 0.1, 0.2, 0.7, 2.5])
    s = np.array([2, 1, 1, 1, 1])
    cuts = list(range(1, t.size))
    lengths = {1: 0.5, 2: 2.0}
    by_time = _run(t, s, lengths, cuts, "time")
    by_radar = _run(t, s, lengths, cuts, "radar")
    assert [(g[2], g[1], g[3]) for g in by_time] == [
        ([0], 0.0, 5), ([1, 2], 0.2, 5), ([3], 0.7, 5), ([4], 2.5, 6)]
    assert [(g[2], g[1], g[3]) for g in by_radar] == [
        ([1, 2], 0.2, 4), ([0], 0.2, 5), ([3], 0.7, 5), ([4], 2.5, 6)]


def test_radar_release_waits_for_no_slow_radar() -> None:
    # a fast radar (frames of 0.5 s, a plot every 0.1 s) and a sparse slow one (frames of
    # 1.5 s, one plot at the start of each): by radar each fast frame goes at the next
    # plot of its own radar; in time order some wait for the slow radar's frame to close
    t = np.round(np.arange(300) * 0.1, 6)
    s = np.where(np.arange(300) % 16 == 0, 2, 1)
    cuts = list(range(1, t.size))
    lengths = {1: 0.5, 2: 1.5}
    lag = {}
    for release in ("time", "radar"):
        lag[release] = {tuple(g[2]): t[g[4] - 1] - t[g[2]].max()
                        for g in _run(t, s, lengths, cuts, release)
                        if g[4] < t.size and s[g[2][0]] == 1}
    assert lag["time"].keys() <= lag["radar"].keys()  # by time more wait for the end
    assert max(lag["radar"].values()) <= 0.2 + 1e-9  # one or two steps: own next plots
    assert max(lag["time"].values()) > 1.0  # behind the slow radar's open frame


def test_unknown_release_refused() -> None:
    with pytest.raises(ValueError, match="unknown release 'sector'"):
        Framer(1.0, release="sector")
