"""Accuracy study of a clutter-intensity estimator: feed it every scan of a simulation,
time it and score it against the true intensity (``mhtrack clutter``).

:func:`clutter_accuracy` runs an estimator over a simulation, feeding it every scan. By
default it passes no gate mask (``in_track_gates=None``): the estimator sees all plots,
target plots included, as it would before any track is confirmed. With
``oracle_gates=True`` it passes the true target plots (``origin ≥ 0``) as the mask, which
an estimator built with ``source="outside-gates"`` leaves out — the accuracy it would have
behind perfect gates. The scores (integrated absolute error, count errors, the
quadrature check) are the pure formulas of :mod:`mhtrack.metrics.clutter`.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.radar_map import MapSnapshot, map_snapshots
from mhtrack.metrics.clutter import (
    DEFAULT_RESOLUTION,
    integrated_absolute_error,
    quadrature_relative_error,
    true_intensity_grid,
)
from mhtrack.models.clutter import Region
from mhtrack.scenario import Simulation


@dataclass(frozen=True)
class ClutterAccuracy:
    """Per-scan accuracy of one estimator over one simulation (see :mod:`mhtrack.metrics.clutter`).

    Arrays are per scan, in scan order. ``maps`` holds, for each requested scan, the true
    and estimated intensity on the ``resolution × resolution`` grid (rows = y, columns = x).
    """

    estimator: str
    region: Region
    resolution: int
    scans: np.ndarray
    iae: np.ndarray
    count_hat: np.ndarray
    rate: np.ndarray
    n_clutter: np.ndarray
    quadrature_error: np.ndarray
    update_seconds: np.ndarray
    maps: dict[int, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict, repr=False)
    #: at each of ``snapshot_scans``, the clutter maps the estimator holds, by sensor id
    #: (:func:`~mhtrack.clutter.radar_map.map_snapshots`; empty for other estimators)
    snapshots: list[dict[int, MapSnapshot]] = field(default_factory=list, repr=False)

    @property
    def count_error(self) -> np.ndarray:
        """``|M̂_k − S λ_k|`` per scan."""
        return np.abs(self.count_hat - self.rate)

    @property
    def count_error_actual(self) -> np.ndarray:
        """``|M̂_k − m_k|`` per scan (``m_k`` clutter plots actually drawn)."""
        return np.abs(self.count_hat - self.n_clutter)

    def _mean(self, a: np.ndarray) -> float:
        return float(a.mean()) if a.size else float("nan")

    @property
    def iae_mean(self) -> float:
        return self._mean(self.iae)

    @property
    def count_error_mean(self) -> float:
        return self._mean(self.count_error)

    def to_dict(self) -> dict[str, Any]:
        """Means and per-scan arrays (as lists), JSON-ready."""
        return {
            "estimator": self.estimator,
            "iae_mean": self.iae_mean,
            "count_error_mean": self.count_error_mean,
            "count_error_actual_mean": self._mean(self.count_error_actual),
            "rate_mean": self._mean(self.rate),
            "ms_per_update": 1e3 * self._mean(self.update_seconds),
            "resolution": self.resolution,
            "quadrature_error_max": float(self.quadrature_error.max())
            if self.quadrature_error.size else float("nan"),
            "scans": self.scans.tolist(),
            "iae": self.iae.tolist(),
            "count_hat": self.count_hat.tolist(),
            "rate": self.rate.tolist(),
            "n_clutter": self.n_clutter.tolist(),
            "count_error": self.count_error.tolist(),
        }


def clutter_accuracy(
    estimator: ClutterEstimator,
    simulation: Simulation,
    *,
    resolution: int = DEFAULT_RESOLUTION,
    oracle_gates: bool = False,
    map_scans: Iterable[int] = (),
    snapshot_scans: Iterable[int] = (),
) -> ClutterAccuracy:
    """Feed ``estimator`` every scan of ``simulation`` and score it per scan.

    Parameters
    ----------
    estimator : a fresh :class:`~mhtrack.clutter.base.ClutterEstimator`.
    simulation : from :func:`mhtrack.scenario.simulate` (plots need ``origin``).
    resolution : cells per side of the IAE grid (``Region.grid``).
    oracle_gates : pass the true target plots as ``in_track_gates`` (default: ``None``).
    map_scans : scans whose true and estimated intensity grids to keep in ``maps``.
    snapshot_scans : scans at which to keep the estimator's clutter maps in ``snapshots``.
    """
    if not (isinstance(resolution, int | np.integer) and resolution >= 2):
        raise ValueError(f"resolution must be an integer >= 2, got {resolution!r}")
    plots = simulation.plots
    if oracle_gates and plots.origin is None:
        raise ValueError("oracle_gates needs plots with a known origin")
    region = simulation.scenario.region
    grid, cell = region.grid(int(resolution))
    want = {int(k) for k in map_scans}
    snap_at = {int(k) for k in snapshot_scans}
    snapshots: list[dict[int, MapSnapshot]] = []
    cache: dict[str, Any] = {}
    rows: dict[str, list[float]] = {k: [] for k in
                                    ("scan", "iae", "count", "rate", "ncl", "quad", "sec")}
    maps: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    n_sensors = len(simulation.scenario.sensors)
    for scan in plots.scans():
        k = int(scan.index)
        mask = (scan.origin >= 0) if oracle_gates and scan.origin is not None else None
        t0 = time.perf_counter()
        estimator.update(scan, mask)
        estimator.intensity(scan.z)
        rows["sec"].append(time.perf_counter() - t0)
        est = np.asarray(estimator.intensity(grid), float)
        true = true_intensity_grid(simulation, k, grid, cache)
        lam = n_sensors * simulation.scenario.clutter_rate(k)
        rows["scan"].append(k)
        rows["iae"].append(integrated_absolute_error(est, true, cell))
        count = getattr(estimator, "count_", None)
        rows["count"].append(float(count) if count is not None else float(est.sum() * cell))
        rows["rate"].append(lam)
        rows["ncl"].append(float((scan.origin < 0).sum()) if scan.origin is not None
                           else float("nan"))
        rows["quad"].append(quadrature_relative_error(true, cell, lam))
        if k in snap_at and (snap := map_snapshots(estimator, float(scan.time))):
            snapshots.append(snap)
        if k in want:
            n = int(resolution)
            maps[k] = (true.reshape(n, n), est.reshape(n, n))
    a = {k: np.asarray(v, float) for k, v in rows.items()}
    return ClutterAccuracy(
        estimator=str(getattr(estimator, "name", type(estimator).__name__)),
        region=region,
        resolution=int(resolution),
        scans=a["scan"].astype(np.int64),
        iae=a["iae"],
        count_hat=a["count"],
        rate=a["rate"],
        n_clutter=a["ncl"],
        quadrature_error=a["quad"],
        update_seconds=a["sec"],
        maps=maps,
        snapshots=snapshots,
    )
