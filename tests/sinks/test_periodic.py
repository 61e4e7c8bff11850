"""The period output (:mod:`mhtrack.sinks.periodic`): ticks worked by hand — which ticks go
out when, from which picture, extrapolated how far — and the limits on extrapolation."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.records import TrackTable
from mhtrack.sinks import TrackCollector
from mhtrack.sinks.periodic import PeriodicSink, empty_frame, extrapolate


def _tracks(ids: list[int], t: list[float], x: list[float], vx: list[float]) -> TrackTable:
    n = len(ids)
    return TrackTable(scan=np.zeros(n, np.int64), time=np.array(t, float),
                      track_id=np.array(ids, np.int64), x=np.array(x, float),
                      y=np.zeros(n), vx=np.array(vx, float), vy=np.full(n, 2.0),
                      plot=np.array([5] * n, np.int64), P=np.ones((n, 4, 4)),
                      tentative=np.zeros(n, bool))


def _out(t: float) -> SimpleNamespace:
    return SimpleNamespace(frame=empty_frame(0, t), stats=None)


def test_extrapolate_by_hand() -> None:
    got = extrapolate(_tracks([7, 9], [10.0, 12.0], [100.0, -50.0], [3.0, -1.0]), 14.0, 3)
    assert got.x.tolist() == [112.0, -52.0]  # 100 + 3 x 4, -50 - 1 x 2
    assert got.y.tolist() == [8.0, 4.0]  # 0 + 2 x 4, 0 + 2 x 2
    assert got.time.tolist() == [14.0, 14.0] and got.scan.tolist() == [3, 3]
    assert got.vx.tolist() == [3.0, -1.0] and got.P is None
    assert got.plot.tolist() == [5, 5]  # the last report's plot: coasting flag unchanged


def test_ticks_by_hand() -> None:
    """Frames at 1, 3, 9 and 9.5 s, period 4 s: the first tick is 4 s (at or after 1 s);
    it and 8 s go out when the frame at 9 s comes, from the picture after the frame at
    3 s; at the end nothing more (12 s is after the last frame)."""
    pictures = {1.0: _tracks([1], [1.0], [0.0], [10.0]),
                3.0: _tracks([1, 2], [3.0, 2.5], [20.0, 0.0], [10.0, 1.0]),
                9.0: _tracks([2], [9.0], [6.5], [1.0]),
                9.5: _tracks([2], [9.5], [7.0], [1.0])}
    down = TrackCollector("online")
    sink = PeriodicSink([down], 4.0, lambda out: pictures[out.frame.time])
    sink.start(None)
    for t in (1.0, 3.0):
        sink.write(_out(t))
    assert len(down.tracks()) == 0 and sink.next_tick == 1
    sink.write(_out(9.0))
    got = down.tracks()
    assert got.scan.tolist() == [1, 1, 2, 2] and got.time.tolist() == [4.0, 4.0, 8.0, 8.0]
    assert got.track_id.tolist() == [1, 2, 1, 2]
    # track 1: 20 + 10 (4 − 3), 20 + 10 (8 − 3); track 2: 0 + 1 (4 − 2.5), 0 + 1 (8 − 2.5)
    assert got.x.tolist() == [30.0, 1.5, 70.0, 5.5]
    sink.write(_out(9.5))
    sink.close()
    assert sink.ticks == 2 and len(down.tracks()) == 4 and sink.next_tick == 3


def test_a_tick_at_a_frame_time_goes_out_at_the_end() -> None:
    down = TrackCollector("online")
    sink = PeriodicSink([down], 2.0, lambda out: _tracks([4], [out.frame.time], [1.0],
                                                         [0.0]))
    sink.write(_out(3.0))
    sink.write(_out(6.0))  # tick 4 s from the frame at 3 s; tick 6 s waits
    assert down.tracks().time.tolist() == [4.0]
    sink.close()  # the end: tick 6 s from the picture of the frame at 6 s
    assert down.tracks().time.tolist() == [4.0, 6.0]


def test_extrapolation_limits() -> None:
    """A gap in the data longer than the limit sends no tick; a track older than it is
    left out of a tick."""
    down = TrackCollector("online")
    pics = {0.0: _tracks([1, 2], [0.0, -5.0], [0.0, 0.0], [1.0, 1.0]),
            20.0: _tracks([1], [20.0], [0.0], [1.0])}
    sink = PeriodicSink([down], 1.0, lambda out: pics[out.frame.time],
                        max_extrapolation_s=3.0)
    sink.write(_out(0.0))
    sink.write(_out(20.0))
    got = down.tracks()
    # ticks 0 (at the first frame's time) to 3 s from the picture at 0 s, without track
    # 2 (5 s old at 0 s); ticks 4 to 19 s would extrapolate more than 3 s: none
    assert got.time.tolist() == [0.0, 1.0, 2.0, 3.0] and set(got.track_id.tolist()) == {1}
    assert sink.skipped == 16 and sink.stale == 4  # ticks 4..19; track 2 in ticks 0..3


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(0.01, 5.0), min_size=1, max_size=30), st.floats(0.5, 6.0))
def test_every_tick_once_in_order(gaps: list[float], period: float) -> None:
    """Over any frame times, each tick from the first frame's to the last's goes out
    once, in order, and rows only after the frames at or before it."""
    times = np.cumsum(gaps).tolist()
    seen: list[float] = []
    sink = PeriodicSink([], period, lambda out: _tracks([1], [out.frame.time], [0.0],
                                                        [0.0]))
    sink.sinks = [SimpleNamespace(write=lambda out: seen.append(out.frame.time),
                                  start=lambda s: None, close=lambda: None)]
    for t in times:
        sink.write(_out(t))
    sink.close()
    k0 = int(np.ceil(times[0] / period))
    expect = [k * period for k in range(k0, int(np.floor(times[-1] / period)) + 1)]
    assert seen == pytest.approx(expect)
