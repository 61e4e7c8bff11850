"""The clutter estimators compared by ``reproduce clutter-scenes``
(:mod:`mhtrack.experiments.clutter_scenes`), by name, each as the tracker of rotating radars
holds it: one estimate per radar, ``κ̂_s(x)`` per m² per rotation.

* ``known`` — the scene's true ``κ_s(x, t)`` (:class:`TrueRadarClutter`, an oracle: the
  best any estimator can do; :mod:`mhtrack.scenario.scene_truth`);
* ``uniform`` — ``κ̂_s = M̄_s / (π R_s²)`` inside the radar's reach ``R_s`` (0 beyond):
  ``M̄_s`` the mean plot count of its last ``W = 5`` rotations, the plots the tracker gave
  to confirmed tracks left out (:class:`DiscUniformClutter`);
* every other name of :data:`mhtrack.build.CLUTTER_ESTIMATOR_CLASSES` (today ``gmm``,
  ``agmm``; an estimator registered there joins the study by its name) — the tracker's own
  per-radar assembly (:func:`mhtrack.build.radar_clutter`: one estimator per radar, fed a
  rotation at a time, in the radar's range and bearing);
* the variants of :data:`VARIANTS` — a registered estimator with keywords: the clutter map
  driving the birth density (``map-birth``, β = 1) and the ablations of the new estimators'
  components (no shrinkage, no forgetting of tracks' plots; no forgetting, no split/merge).

Every registered estimator and variant is run by the tracker built the normal way
(:func:`method_tracker`: ``mht-<estimator>`` with the variant's ``clutter_params``, through
:func:`mhtrack.build.make_tracker`), so what only the build does (``birth_scaling``'s birth
wrapper) acts as it does in ``mhtrack run``; an estimator registered without a tracker name
is given to ``mht-gmm``'s tracker in place of its own (:func:`make_method`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.records import Scan

ORACLE, UNIFORM = "known", "uniform"
UNIFORM_WINDOW = 5
#: Variant name → (registered estimator, its keywords): ``map-birth`` the clutter map
#: driving the birth density; the others switch one component off (the ablation).
VARIANTS: dict[str, tuple[str, dict[str, Any]]] = {
    "map-birth": ("map", {"birth_scaling": 1.0}),
    "mapgmm-birth": ("mapgmm", {"birth_scaling": 1.0}),
    "map-no-shrinkage": ("map", {"prior_weight": 0.0}),
    "map-keeps-track-plots": ("map", {"forget_used": False}),
    "mapgmm-fixed-shrinkage": ("mapgmm", {"prior_count": 5.0}),
    "mapgmm-no-smoothing": ("mapgmm", {"smoothing": 0}),
    "fgmm-no-forgetting": ("fgmm", {"forgetting": 1.0}),
    "fgmm-no-split-merge": ("fgmm", {"merge_distance": 0.0, "split_kurtosis": 0.0}),
}
#: The variants run by default (the ablations only when asked for by name).
DEFAULT_VARIANTS = ("map-birth", "mapgmm-birth")
#: What each fixed method is; the registered estimators are described by their class.
DESCRIPTIONS = {
    ORACLE: "true κ_s(x, t) of the scene at every frame (oracle)",
    UNIFORM: "κ̂ = mean plot count of the radar's last 5 rotations / (π R²), inside its reach",
    "map-birth": "clutter map driving the birth density, s(z) = min(1, ρ̄/κ̂(z))^β, β = 1",
    "mapgmm-birth": "map-calibrated GMM, its map driving the birth density (β = 1)",
    "map-no-shrinkage": "clutter map without the shrinkage toward its mean (b₀ = 0)",
    "map-keeps-track-plots": "clutter map that keeps the plots confirmed tracks used",
    "mapgmm-fixed-shrinkage": "map-calibrated GMM with the former fixed shrinkage, φb = 5 plots",
    "mapgmm-no-smoothing": "map-calibrated GMM without smoothing the counts (0 passes)",
    "fgmm-no-forgetting": "forgetting mixture with γ = 1 (no forgetting)",
    "fgmm-no-split-merge": "forgetting mixture without split and merge",
}


def estimator_methods() -> tuple[str, ...]:
    """The registered estimators the study runs (every name but the constant ``known``)."""
    from mhtrack.build import CLUTTER_ESTIMATOR_CLASSES

    return tuple(n for n in CLUTTER_ESTIMATOR_CLASSES if n != "known")


def all_methods() -> tuple[str, ...]:
    """The default methods: ``known``, ``uniform``, :func:`estimator_methods` and
    :data:`DEFAULT_VARIANTS`, in report order."""
    return (ORACLE, UNIFORM, *estimator_methods(), *DEFAULT_VARIANTS)


def known_methods() -> tuple[str, ...]:
    """Every method the study can run: :func:`all_methods` and every variant."""
    return (*all_methods(), *(v for v in VARIANTS if v not in DEFAULT_VARIANTS))


def method_tracker(method: str, params: Mapping[str, Any] | None = None
                   ) -> tuple[str, dict[str, Any]]:
    """The tracker name (``mht-<estimator>``, :data:`mhtrack.build.TRACKER_ESTIMATORS`) and
    clutter keywords (the variant's, then ``params``) of a registered estimator or variant."""
    from mhtrack.build import TRACKER_ESTIMATORS

    est, kw = VARIANTS.get(method, (method, {}))
    if est not in estimator_methods():
        raise ValueError(f"{method!r} is not a registered clutter estimator or variant")
    by_estimator = {e: t for t, e in TRACKER_ESTIMATORS.items()}
    if est not in by_estimator:
        raise ValueError(f"{method!r}: no tracker uses estimator {est!r}")
    return by_estimator[est], {**kw, **dict(params or {})}


def has_tracker(method: str) -> bool:
    """Whether a tracker of :data:`mhtrack.build.TRACKER_ESTIMATORS` uses ``method``'s
    estimator (an estimator registered without one is given to ``mht-gmm``'s tracker)."""
    from mhtrack.build import TRACKER_ESTIMATORS

    if method in (ORACLE, UNIFORM):
        return False
    return VARIANTS.get(method, (method, {}))[0] in TRACKER_ESTIMATORS.values()


def describe(method: str) -> str:
    """One line on ``method``."""
    if method in DESCRIPTIONS:
        return DESCRIPTIONS[method]
    from mhtrack.build import CLUTTER_ESTIMATOR_CLASSES

    doc = (CLUTTER_ESTIMATOR_CLASSES[method].__doc__ or method).strip().split("\n\n")[0]
    return " ".join(doc.split())


class TrueRadarClutter(ClutterEstimator):
    """The true ``κ_s(x, t)`` of the last frame's radar at the frame's time
    (:class:`~mhtrack.scenario.scene_truth.RadarTruth`, evaluated at any points)."""

    name = "true-radar"

    def __init__(self, scenario: Any) -> None:
        from mhtrack.scenario.scene_truth import RadarTruth

        self.truth = RadarTruth(scenario)
        self.sensor: int | None = None
        self.time = 0.0

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        ids = np.unique(np.asarray(scan.sensor, np.int64))
        if ids.size:
            self.sensor = int(ids[0])
        self.time = float(scan.time)

    def intensity(self, z: np.ndarray) -> np.ndarray:
        z = np.asarray(z, float).reshape(-1, 2)
        if self.sensor is None:
            return np.zeros(len(z))
        return self.truth.intensity(self.sensor, self.time, z)

    def get_state(self) -> dict[str, Any]:
        return {"sensor": self.sensor, "time": self.time}

    def set_state(self, state: dict[str, Any]) -> None:
        self.sensor, self.time = state["sensor"], float(state["time"])


class DiscUniformClutter(ClutterEstimator):
    """``κ̂ = M̄ / (π R²)`` within ``R`` of ``site`` (module docstring); fed whole rotations
    by :class:`~mhtrack.clutter.per_sensor.PerSensorClutter`."""

    name = "disc-uniform"

    def __init__(self, site: tuple[float, float], reach: float,
                 window: int = UNIFORM_WINDOW) -> None:
        self.site, self.reach, self.window = (float(site[0]), float(site[1])), float(reach), window
        self.counts: list[int] = []

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        self.counts = [*self.counts, len(scan)][-self.window:]

    def intensity(self, z: np.ndarray) -> np.ndarray:
        z = np.asarray(z, float).reshape(-1, 2)
        inside = np.hypot(z[:, 0] - self.site[0], z[:, 1] - self.site[1]) <= self.reach
        m = float(np.mean(self.counts)) if self.counts else 0.0
        return np.where(inside, m / (np.pi * self.reach ** 2), 0.0)

    def get_state(self) -> dict[str, Any]:
        return {"counts": list(self.counts)}

    def set_state(self, state: dict[str, Any]) -> None:
        self.counts = [int(c) for c in state["counts"]]


def make_method(method: str, scenario: Any,
                params: Mapping[str, Any] | None = None) -> ClutterEstimator:
    """A fresh per-radar estimator of ``method`` for a rotating-radar ``scenario``."""
    from mhtrack.build import radar_clutter
    from mhtrack.clutter.per_sensor import PerSensorClutter

    sensors = scenario.sensor_set()
    if method == ORACLE:
        return TrueRadarClutter(scenario)
    if method == UNIFORM:
        reach = {s.id: s.max_range for s in scenario.sensors}

        def disc(sid: int, _inner: ClutterEstimator) -> ClutterEstimator:
            if reach[sid] is None:
                raise ValueError(f"sensor {sid}: the uniform baseline needs max_range")
            return DiscUniformClutter(sensors.site_xy(sid), float(reach[sid]))

        # ``disc`` makes each radar's estimator; the inner one ``make`` gives is unused
        return PerSensorClutter(lambda: DiscUniformClutter((0.0, 0.0), 1.0),
                                {s.id: s.period for s in sensors.sensors}, wrap=disc)
    if method not in estimator_methods():
        raise ValueError(f"unknown method {method!r} (expected {', '.join(all_methods())})")
    return radar_clutter(method, sensors, params=dict(params or {}))
