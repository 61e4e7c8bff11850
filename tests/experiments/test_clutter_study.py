"""The clutter-accuracy study (``experiments.clutter_study``): an oracle and the true
uniform density score IAE 0, count errors by hand, oracle gates feed only clutter."""

from typing import Any

import numpy as np
import pytest

from mhtrack.clutter import AGMMClutter, KnownClutter
from mhtrack.experiments.clutter_study import clutter_accuracy
from mhtrack.metrics.clutter import DEFAULT_RESOLUTION, true_intensity_grid, uniform_guess
from mhtrack.models.clutter import Region
from mhtrack.records import Scan
from mhtrack.scenario import preset, simulate

REGION = Region(-4000.0, 4000.0, -4000.0, 4000.0)


class _Oracle:
    """An estimator that knows the true intensity of the simulation (IAE must be 0)."""

    name = "oracle"

    def __init__(self, sim: Any) -> None:
        self.sim, self.k = sim, 0

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        self.k = scan.index

    def intensity(self, z: np.ndarray) -> np.ndarray:
        return true_intensity_grid(self.sim, self.k, np.asarray(z).reshape(-1, 2))

    def get_state(self) -> dict[str, Any]:
        return {"k": self.k}

    def set_state(self, state: dict[str, Any]) -> None:
        self.k = state["k"]


def test_oracle_and_uniform_known_on_uniform_clutter() -> None:
    sim = simulate(preset("crossing", scans=4, clutter="uniform", clutter_rate=25.0), seed=3)
    acc = clutter_accuracy(_Oracle(sim), sim, resolution=50)
    np.testing.assert_allclose(acc.iae, 0.0, atol=1e-12)
    assert uniform_guess(sim) == pytest.approx(25.0 / REGION.area)
    known = clutter_accuracy(KnownClutter(uniform_guess(sim)), sim, resolution=50)
    np.testing.assert_allclose(known.iae, 0.0, atol=1e-12)
    np.testing.assert_allclose(known.count_hat, 25.0)
    np.testing.assert_allclose(known.count_error, 0.0, atol=1e-9)
    # the actual clutter counts are the simulation's
    n_cl = [int((s.origin < 0).sum()) for s in sim.plots.scans()]
    np.testing.assert_array_equal(known.n_clutter, n_cl)
    np.testing.assert_allclose(known.count_error_actual, np.abs(25.0 - np.array(n_cl)))


def test_count_errors_by_hand_and_to_dict() -> None:
    sim = simulate(preset("crossing", scans=3), seed=2)
    acc = clutter_accuracy(AGMMClutter(window=2), sim, resolution=40, map_scans=[2])
    counts = [len(s) for s in sim.plots.scans()]
    want = [counts[0], np.mean(counts[:2]), np.mean(counts[1:3])]  # all plots, window 2
    np.testing.assert_allclose(acc.count_hat, want)
    np.testing.assert_allclose(acc.count_error, np.abs(np.array(want) - 40.0))
    d = acc.to_dict()
    assert d["iae_mean"] == pytest.approx(acc.iae.mean())
    assert d["count_error_mean"] == pytest.approx(np.mean(np.abs(np.array(want) - 40.0)))
    true_map, est_map = acc.maps[2]
    assert true_map.shape == est_map.shape == (40, 40)
    # 200 m cells cannot resolve σ ≈ 30 m clumps: the check on the truth's mass says so
    assert acc.quadrature_error.min() > 0.1
    fine = clutter_accuracy(AGMMClutter(), simulate(preset("crossing", scans=1), seed=2))
    assert fine.resolution == DEFAULT_RESOLUTION
    assert fine.quadrature_error.max() < 1e-4


def test_oracle_gates_feed_only_clutter() -> None:
    sim = simulate(preset("crossing", scans=3), seed=2)
    acc = clutter_accuracy(AGMMClutter(window=1, source="outside-gates"), sim,
                           resolution=40, oracle_gates=True)
    np.testing.assert_allclose(acc.count_hat, acc.n_clutter)


def test_resolution_check() -> None:
    sim = simulate(preset("crossing", scans=2), seed=0)
    with pytest.raises(ValueError, match="resolution"):
        clutter_accuracy(KnownClutter(), sim, resolution=1)
