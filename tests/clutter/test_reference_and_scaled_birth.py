"""The clutter-scaled birth forwards every hook of the process it wraps, and
``reference_intensity`` is part of the clutter-estimator interface (so no wrapper drops it)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from mhtrack.build import make_tracker
from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.per_sensor import PerSensorClutter
from mhtrack.clutter.polar import PolarClutter
from mhtrack.clutter.radar_map import ClutterMap
from mhtrack.mht.births.clutter_scaled import ClutterScaledBirth
from mhtrack.mht.config import MHTConfig
from mhtrack.records import Scan
from mhtrack.scenario import preset, simulate


class _Flat(ClutterEstimator):
    name = "flat"

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        pass

    def intensity(self, z: np.ndarray) -> np.ndarray:
        return np.full(len(z), 1e-8)

    def get_state(self) -> dict:
        return {}

    def set_state(self, state: dict) -> None:
        pass


def _scan(z: np.ndarray, sensor: int = 1, k: int = 0, t: float = 0.0) -> Scan:
    n = len(z)
    return Scan(k, t, z, np.full(n, sensor), np.arange(n), t=np.full(n, t))


def test_an_estimator_without_a_reference_has_zero() -> None:
    assert _Flat().reference_intensity() == 0.0


def test_wrappers_forward_the_maps_mean() -> None:
    """``ρ̄ = Σ S_c / (N A)``: 40 plots in one rotation of a 10 km map is 40 / (π 10⁸)."""
    m = ClutterMap(range_cell=1000.0, max_range=10_000.0)
    rng = np.random.default_rng(3)
    z = rng.uniform(-5000.0, 5000.0, (40, 2))
    m.update(_scan(z))
    expect = 40 / (np.pi * 1e8)
    assert m.reference_intensity() == pytest.approx(expect, rel=1e-12)
    assert PolarClutter(m, (0.0, 0.0)).reference_intensity() == m.reference_intensity()
    per = PerSensorClutter(lambda: ClutterMap(range_cell=1000.0, max_range=10_000.0))
    assert per.reference_intensity() == 0.0  # no sensor fed yet
    per.update(_scan(z))
    assert per.reference_intensity() == pytest.approx(expect, rel=1e-12)
    assert PerSensorClutter(_Flat).reference_intensity() == 0.0


def test_scaled_birth_keeps_the_start_up_density() -> None:
    """With ``startup_density`` the wrapped every-plot birth's undetected density follows
    the recursion ``D ← (1 − P_D)(D + λ_v)`` exactly as without the wrapper (the first scan
    sets it from the same map); a wrapper that dropped the hook left the inner density
    ``None``."""
    sim = simulate(preset("crossing", scans=8), seed=2)
    cfg = replace(MHTConfig(), startup_density=True)
    scaled = make_tracker("mht-map", cfg, clutter_params={"birth_scaling": 1.0})
    plain = make_tracker("mht-map", cfg)
    assert isinstance(scaled.birth, ClutterScaledBirth)
    for s in sim.plots.scans():
        scaled.step(s)
        plain.step(s)
        a, b = scaled.birth.inner.undetected.density, plain.birth.undetected.density
        assert a is not None and a == pytest.approx(b, rel=1e-12)
