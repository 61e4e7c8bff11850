"""PerSensorClutter: one estimator per radar, fed a rotation at a time."""

from __future__ import annotations

import numpy as np

from mhtrack.clutter.known import KnownClutter
from mhtrack.clutter.per_sensor import PerSensorClutter
from mhtrack.mht.state import decode, encode
from mhtrack.records import Scan


class Counting(KnownClutter):
    """κ = number of plots of the last scan it was given (to see what each one got)."""

    def update(self, scan, in_track_gates=None):
        self.kappa = float(len(scan))


def _frame(k, sensor, times):
    t = np.asarray(times, float)
    return Scan(k, float(t.max()), np.zeros((t.size, 2)), np.full(t.size, sensor),
                np.arange(t.size) + 100 * k, t=t)


def test_each_sensor_gets_its_own_rotations():
    est = PerSensorClutter(lambda: Counting(1.0), {1: 4.0, 2: 6.0}, initial=7.0)
    est.update(_frame(0, 1, [0.0, 0.5]))
    assert est.intensity(np.zeros((1, 2))).tolist() == [7.0]  # no full rotation yet
    est.update(_frame(1, 2, [0.2, 1.0, 1.5]))
    est.update(_frame(2, 1, [2.0, 3.0, 3.5]))
    est.update(_frame(3, 1, [4.1]))  # sensor 1's rotation [0, 4) complete: 5 plots
    assert est.intensity(np.zeros((1, 2))).tolist() == [5.0]
    est.update(_frame(4, 2, [6.5]))  # sensor 2's: 3 plots, none of sensor 1's
    assert est.intensity(np.zeros((1, 2))).tolist() == [3.0]


def test_state_round_trip():
    est = PerSensorClutter(lambda: Counting(1.0), {1: 4.0})
    for k, t in enumerate([[0.0], [2.0, 3.0], [4.5]]):
        est.update(_frame(k, 1, t))
    arrays: dict = {}
    state = decode(encode(est.get_state(), arrays), arrays)
    back = PerSensorClutter(lambda: Counting(1.0), {1: 4.0})
    back.set_state(state)
    for e in (est, back):
        e.update(_frame(9, 1, [8.6]))
    assert est.intensity(np.zeros((1, 2))).tolist() == back.intensity(np.zeros((1, 2))).tolist()
