"""The monotonic time axis of ASTERIX times of day: hand-worked steps, and the true times
recovered from their times of day (with capture times, and without)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.io.asterix.timeaxis import DAY_S, MAX_LATE_S, TimeAxis, unwrap_days


def test_midnight_without_capture_times() -> None:
    # 23:59:59, 23:59:59.9, 00:00:00.2 (next day), 23:59:59.95 (late, previous day),
    # 00:00:00.5, 00:00:10
    tod = [86399.0, 86399.9, 0.2, 86399.95, 0.5, 10.0]
    assert unwrap_days(np.array(tod)).tolist() == [86399.0, 86399.9, 86400.2, 86399.95,
                                                   86400.5, 86410.0]


def test_gap_of_13_hours_without_capture_times() -> None:
    # 01:00 then 14:00 (13 h later, same day); then 01:59:59, a step back of 12 h 0 min
    # 1 s: the next day; while 02:00, a step back of exactly 12 h, is a late plot of day 0
    axis = TimeAxis()
    assert axis.times([3600.0, 50400.0]).tolist() == [3600.0, 50400.0]
    assert axis.times([7199.0]).tolist() == [7199.0 + DAY_S]  # 12 h 0 min 1 s back
    assert TimeAxis().times([3600.0, 50400.0, 7200.0]).tolist() == [3600.0, 50400.0, 7200.0]


def test_previous_day_only_within_max_late() -> None:
    axis = TimeAxis()
    axis.times([DAY_S - 10.0, 20.0])  # 23:59:50, then 00:00:20 of day 1
    # 23:30 is 30.3 min before the latest time: a late plot of day 0
    assert axis.times([DAY_S - 1800.0]).tolist() == [DAY_S - 1800.0]
    # 00:00:20 + 22 h: a forward step of 22 h, same day
    assert axis.times([20.0 + 22 * 3600.0]).tolist() == [DAY_S + 20.0 + 22 * 3600.0]
    assert MAX_LATE_S == 3600.0


def test_capture_times_choose_the_day() -> None:
    day = 19_000 * DAY_S  # some date
    axis = TimeAxis()
    # 23:59:58 captured at 23:59:58.3; 00:00:01 captured at 00:00:01.1 the next day
    assert axis.times([86398.0], day + 86398.3).tolist() == [86398.0]
    assert axis.times([1.0], day + DAY_S + 1.1).tolist() == [DAY_S + 1.0]
    # 13 h later, by the capture clock; then three days later
    assert axis.times([46801.0], day + DAY_S + 46801.0).tolist() == [DAY_S + 46801.0]
    assert axis.times([5.0, 6.0], day + 4 * DAY_S + 5.5).tolist() == [4 * DAY_S + 5.0,
                                                                       4 * DAY_S + 6.0]


@st.composite
def journeys(draw, max_gap: float):
    """Increasing true times (multiples of 1/128 s, exact in float) with jitter back,
    starting anywhere in a day."""
    t0 = draw(st.integers(0, 86400 * 128 - 1)) / 128
    steps = draw(st.lists(st.one_of(st.integers(0, 128 * 60), st.integers(0, int(max_gap)
                                                                          * 128)),
                          min_size=1, max_size=40))
    t = t0 + np.cumsum(np.asarray(steps, float) / 128)
    jitter = np.asarray(draw(st.lists(st.integers(0, 128 * 5), min_size=t.size,
                                      max_size=t.size)), float) / 128
    return np.maximum(t - jitter, t0)


@settings(max_examples=200, deadline=None)
@given(journeys(max_gap=12 * 3600 - 60))
def test_true_times_back_without_capture(t) -> None:
    # gaps below 12 h and jitter of up to 5 s: the rule recovers every time (a longer
    # gap that ends past midnight looks like a late plot: capture times tell them apart)
    tod = np.mod(t, DAY_S)
    day0 = np.floor(t[0] / DAY_S) * DAY_S
    assert np.array_equal(TimeAxis().times(tod), t - day0)


@settings(max_examples=200, deadline=None)
@given(journeys(max_gap=5 * 86400), st.integers(0, 30_000),
       st.floats(-6 * 3600, 6 * 3600))
def test_true_times_back_with_capture(t, date, clock_error) -> None:
    # any gap (days), with a capture clock off by up to 6 h
    t = t + date * DAY_S
    tod = np.mod(t, DAY_S)
    axis = TimeAxis()
    got = np.concatenate([axis.times(tod[i:i + 1], float(t[i]) + clock_error)
                          for i in range(t.size)])
    assert np.array_equal(got, t - np.floor(t[0] / DAY_S) * DAY_S)


@pytest.mark.parametrize("tod", [[], [5.0]])
def test_short(tod) -> None:
    assert TimeAxis().times(np.array(tod)).tolist() == tod
