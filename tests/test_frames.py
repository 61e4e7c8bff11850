"""Frames of asynchronous plots: a hand-worked case and the properties every cut must have."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.frames import frame_lengths, make_frames
from mhtrack.records import PlotTable


def test_hand_worked_two_radars() -> None:
    t = np.array([0.0, 0.5, 1.2, 0.3, 0.9, 2.5, 0.1])
    s = np.array([1, 1, 1, 2, 2, 2, 1])
    frame, order = make_frames(t, s, 1.0)
    # radar 1: {0.0, 0.1, 0.5} ends 0.5, {1.2}; radar 2: {0.3, 0.9} ends 0.9, {2.5}
    assert frame.tolist() == [0, 0, 2, 1, 1, 3, 0]
    assert order.tolist() == [0, 6, 1, 3, 4, 2, 5]
    table = PlotTable(scan=frame[order], time=t[order], sensor=s[order], x=np.zeros(7),
                      y=np.zeros(7), timed=True)
    scans = list(table.scans())
    assert [sc.time for sc in scans] == [0.5, 0.9, 1.2, 2.5]
    assert scans[0].t.tolist() == [0.0, 0.1, 0.5] and scans[0].rows.tolist() == [0, 1, 2]


def test_frame_lengths_from_periods() -> None:
    assert frame_lengths({1: 12.0, 2: None}) == {1: 1.5, 2: 1.0}


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 100), st.integers(0, 3)), min_size=1, max_size=60),
       st.floats(0.1, 5.0))
def test_frames_are_one_sensor_short_and_in_end_time_order(plots, length) -> None:
    t = np.array([p[0] for p in plots])
    s = np.array([p[1] for p in plots])
    frame, order = make_frames(t, s, length)
    assert sorted(order.tolist()) == list(range(len(t)))
    assert np.all(np.diff(frame[order]) >= 0)
    ends = []
    for f in np.unique(frame):
        rows = frame == f
        assert np.unique(s[rows]).size == 1          # one sensor per frame
        assert t[rows].max() - t[rows].min() <= length  # no longer than its length
        ends.append(t[rows].max())
    assert np.all(np.diff(ends) >= 0)                # processed in order of end time
