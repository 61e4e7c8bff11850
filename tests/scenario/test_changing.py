"""The crossing-changing preset: its clutter components appear, vanish, split, merge and
drift as documented, and the preset round-trips through its dict form."""

import numpy as np
import pytest

from mhtrack.models.clutter import TimeVaryingClutter
from mhtrack.scenario import PRESETS, Scenario, preset, simulate
from mhtrack.scenario.changing import changing_components


@pytest.fixture(scope="module")
def sc():
    return preset("crossing-changing")


def test_listed_and_same_targets_as_crossing(sc):
    assert "crossing-changing" in PRESETS
    base = preset("crossing")
    assert sc.to_dict()["targets"] == base.to_dict()["targets"]
    assert sc.to_dict()["sensors"] == base.to_dict()["sensors"]
    assert isinstance(sc.clutter, TimeVaryingClutter)
    assert Scenario.from_dict(sc.to_dict()).to_dict() == sc.to_dict()


def test_components_change(sc):
    at = sc.clutter.at
    w1, w35, w90 = at(1).weights, at(35).weights, at(90).weights
    # A vanishes, B appears
    assert w1[0] > 0.2 and w90[0] == 0
    assert w1[1] == 0 and w35[1] > 0 and w90[1] > 0.2
    # C and D: one clump at scan 1, apart at the end (split); E and F the other way
    m1, m90 = at(1).means, at(90).means
    assert np.allclose(m1[2], m1[3])
    assert np.linalg.norm(m90[2] - m90[3]) > 2500
    assert np.linalg.norm(m1[4] - m1[5]) > 2000 and np.allclose(m90[4], m90[5])
    # G drifts linearly from (2800, −3000) to (0, −300)
    assert np.allclose(at(1).means[6], (2800, -3000))
    assert np.allclose(at(45).means[6], (2800 - 2800 * 44 / 89, -3000 + 2700 * 44 / 89))
    assert np.allclose(at(90).means[6], (0, -300))
    # the keyframes follow changing_components between keyframes (means exactly)
    for k in (7, 25, 33, 47, 58, 77):
        assert np.allclose(at(k).means, changing_components(k)[1])


def test_clutter_follows_the_field(sc):
    sim = simulate(sc, seed=5)
    z = sim.plots.z[sim.plots.origin < 0]
    k = sim.plots.scan[sim.plots.origin < 0]
    near_a = np.linalg.norm(z - (-2000, 1000), axis=1) < 600
    # component A (a quarter of the clutter at first) is gone after scan 50
    assert near_a[k <= 20].mean() > 0.15
    assert near_a[k > 55].sum() == 0
    assert sc.clutter.rate(40) == 40.0
