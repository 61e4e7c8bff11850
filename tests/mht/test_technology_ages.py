"""Per-technology update ages (I062/290 PSR, SSR, MDS; issue 29 item 5): a hand-worked
sequence of updates by plots of each type, the ages at a later time; the sensors'
own list is not touched by the technologies kept in the same store."""

from __future__ import annotations

import numpy as np

from mhtrack.attributes import COMBINED, MODE_S, PRIMARY, SECONDARY
from mhtrack.mht.sensor_ages import SensorAges, technology_updates


def test_ages_by_technology_hand_worked():
    ages = SensorAges(memory_s=900.0)
    # track 7: primary at 10 s, combined at 14 s (PSR and SSR), Mode S at 17 s;
    # track 9: secondary at 12 s only; track 4: nothing by type (type 0)
    for t, track, sensor, ptype in ((10.0, 7, 1, PRIMARY), (12.0, 9, 2, SECONDARY),
                                    (14.0, 7, 2, COMBINED), (17.0, 7, 1, MODE_S),
                                    (17.5, 4, 1, 0)):
        tr, ty, w = np.array([track]), np.array([ptype]), np.array([t])
        ages.update(tr, np.array([sensor]), w, t)
        ages.update(*technology_updates(tr, ty, w), t)
    got = ages.technologies(np.array([7, 9, 4, 5]), np.array([20.0, 20.0, 20.0, 20.0]))
    nan = np.nan
    np.testing.assert_array_equal(got, [[6.0, 6.0, 3.0],      # PSR 14, SSR 14, MDS 17
                                        [nan, 8.0, nan],
                                        [nan, nan, nan],
                                        [nan, nan, nan]])
    sensors, sensor_ages = ages.of(np.array([7, 9, 4]), np.array([20.0, 20.0, 20.0]))
    assert sensors.tolist() == ["1;2", "2", "1"]
    assert sensor_ages.tolist() == ["3.000;6.000", "8.000", "2.500"]


def test_ages_are_forgotten_with_the_memory():
    ages = SensorAges(memory_s=5.0)
    ages.update(*technology_updates(np.array([1]), np.array([PRIMARY]), np.array([0.0])), 0.0)
    ages.update(*technology_updates(np.array([2]), np.array([MODE_S]), np.array([9.0])), 9.0)
    got = ages.technologies(np.array([1, 2]), np.array([10.0, 10.0]))
    np.testing.assert_array_equal(got, [[np.nan] * 3, [np.nan, np.nan, 1.0]])
