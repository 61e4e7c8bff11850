"""The clutter map's cells follow the radar's reach unless given; a map told not to forget
the tracks' plots keeps them; the clutter-scenes variants build the tracker of their
estimator through ``make_tracker`` (the birth wrapper of ``map-birth`` included)."""

from __future__ import annotations

import numpy as np
import pytest

from mhtrack.build import make_tracker
from mhtrack.clutter.radar_map import REACH_RINGS, REACH_SECTORS, ClutterMap
from mhtrack.experiments.scene_methods import (
    VARIANTS,
    has_tracker,
    known_methods,
    method_tracker,
)
from mhtrack.mht.births.clutter_scaled import ClutterScaledBirth
from mhtrack.records import Scan
from mhtrack.scenario import preset


@pytest.mark.parametrize("reach", [3_000.0, 50_000.0, 250_000.0])
def test_cells_follow_the_reach(reach):
    m = ClutterMap().placed((10.0, -5.0), reach)
    assert (m.n_rings, m.n_azimuth) == (REACH_RINGS, REACH_SECTORS)
    assert m.range_cell * m.n_rings == pytest.approx(reach)
    # the cells tile the disc of the reach (closed form π R²)
    assert m.areas().sum() == pytest.approx(np.pi * reach**2)


def test_given_cells_are_kept_and_no_reach_keeps_the_old_cells():
    m = ClutterMap(range_cell=700.0, n_azimuth=16).placed((0.0, 0.0), 7_000.0)
    assert (m.range_cell, m.n_azimuth, m.n_rings) == (700.0, 16, 10)
    m = ClutterMap()
    assert (m.range_cell, m.n_azimuth) == (500.0, 64)


def _scan(z):
    z = np.asarray(z, float)
    return Scan(index=0, time=0.0, z=z, sensor=np.zeros(len(z), np.int64),
                rows=np.arange(len(z)))


@pytest.mark.parametrize("forget_used", [True, False])
def test_forget_used_switch(forget_used):
    m = ClutterMap(max_range=2_000.0, forget_used=forget_used)
    m.update(_scan([[100.0, 100.0], [150.0, 120.0], [-900.0, 300.0]]))
    before = m.sums_.sum()
    m.forget(np.array([True, False, True]))
    assert m.sums_.sum() == (before - 2 if forget_used else before)
    assert m.placed((0.0, 0.0)).forget_used is forget_used


def test_variants_build_their_estimators_tracker():
    sensors = preset("radars-clutter", scans=5).sensor_set()
    assert set(VARIANTS) <= set(known_methods())
    assert not has_tracker("known") and not has_tracker("uniform") and has_tracker("gmm")
    assert method_tracker("gmm") == ("mht-gmm", {})
    name, kw = method_tracker("map-birth")
    assert (name, kw) == ("mht-map", {"birth_scaling": 1.0})
    trk = make_tracker(name, sensors=sensors, clutter_params=kw)
    assert isinstance(trk.birth, ClutterScaledBirth)
    plain = make_tracker("mht-map", sensors=sensors)
    assert not isinstance(plain.birth, ClutterScaledBirth)
    name, kw = method_tracker("fgmm-no-split-merge", {"seed": 3})
    assert name == "mht-fgmm" and kw == {"merge_distance": 0.0, "split_kurtosis": 0.0,
                                          "seed": 3}
    with pytest.raises(ValueError, match="not a registered"):
        method_tracker("uniform")


@pytest.mark.parametrize("forget_used", [True, False])
def test_per_radar_rotation_keeps_track_plots_only_when_told(forget_used):
    """On a rotating radar the tracks' plots leave the rotation being gathered, unless the
    map keeps them: after the rotation the map holds 3 or 2 plots."""
    from mhtrack.clutter.per_sensor import PerSensorClutter

    per = PerSensorClutter(lambda: ClutterMap(max_range=5_000.0, forget_used=forget_used),
                           {1: 4.0})

    def frame(t, z):
        z = np.asarray(z, float)
        return Scan(index=0, time=t, z=z, sensor=np.ones(len(z), np.int64),
                    rows=np.arange(len(z)), t=np.full(len(z), t))

    per.update(frame(0.5, [[100.0, 100.0], [900.0, -200.0], [-50.0, 2000.0]]))
    per.forget(np.array([False, True, False]))
    per.update(frame(4.5, [[10.0, 10.0]]))  # the next rotation: the first one is fed
    assert per.estimator(1).sums_.sum() == (3.0 if not forget_used else 2.0)
