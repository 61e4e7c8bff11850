"""The tracker builder: every part by its name, and the MHT's defaults fitted to the data.

The CLI, the experiments and users build trackers here. Each name a user chooses a part
by is listed once in :mod:`mhtrack.names`; this module maps those names to the classes:

* trackers (:data:`~mhtrack.names.TRACKERS`) → the clutter estimator each one runs
  (:data:`TRACKER_ESTIMATORS`), built by :func:`make_tracker`;
* clutter estimators (:data:`~mhtrack.names.CLUTTER_ESTIMATORS`) →
  :data:`CLUTTER_ESTIMATOR_CLASSES`, built by :func:`make_clutter_estimator`;
* initiators (:data:`~mhtrack.names.INITIATORS`) → :data:`INITIATOR_CLASSES`, built by
  :func:`make_initiator`;
* plot fusions (:data:`~mhtrack.names.TRACKER_FUSIONS`,
  :data:`~mhtrack.names.INITIATION_FUSIONS`) → :data:`TRACKER_FUSERS`,
  :data:`INITIATION_FUSER_CLASSES`.

Defaults (:func:`default_config`): P1 §3's parameters, with the new-target density scaled
to the surveillance area (:func:`birth_density_for_area`, the area of a scenario's region
or of a plots file's robust bounding box, :func:`plots_area`) and, with one sensor, that
sensor's ``P_D`` (at most :data:`MAX_TRACKER_PD`) and Cartesian ``σ``.

Layer: after ``mht`` and ``initiation``, before ``metrics`` and ``experiments``; it
imports neither of those, nor plotting or the CLI.
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from mhtrack import names
from mhtrack.clutter.agmm import AGMMClutter
from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.gmm import GMMClutter
from mhtrack.clutter.known import KnownClutter
from mhtrack.clutter.per_sensor import PerSensorClutter
from mhtrack.clutter.polar import PolarClutter
from mhtrack.initiation.factory import INITIATOR_CLASSES, make_initiator
from mhtrack.initiation.fusion import AdaptiveKMeansFusion, KMeansFusion
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.mht.coverage import RadarCoverage
from mhtrack.models.radars import RadarSensor, SensorSet
from mhtrack.models.sensors import CartesianSensor

if TYPE_CHECKING:
    from mhtrack.scenario import Scenario

# ---------------------------------------------------------------- clutter estimators

#: Default known clutter density of the plain MHT (P1 §3: 1e−9 per m²).
DEFAULT_CLUTTER_DENSITY = 1e-9

#: Plots a branch must hold before a tree of asynchronous plots is confirmed. A tree
#: starts from one plot with velocity ``0 ± v_max/2``, so its second plot's
#: ``ln p(z₂|T)`` only says that the two plots lie within ``v_max·Δt`` of each other —
#: any pair does, target or clutter — and every pair of plots makes an exact
#: constant-velocity line. The third plot is the first whose likelihood tests the
#: motion (Blackman & Popoli 1999 §6.3: a track is confirmed on the scans after the two
#: that initiate it). Measured on ``opensky-radars`` seeds 1–3 (``docs/mht.md``,
#: *Asynchronous plots*): on seed 1 all 7 tracks confirmed on clutter and 2 of the 5
#: short duplicates held exactly 2 plots. Synchronous scans keep P1's 2 (bit for bit).
TIMED_CONFIRM_MIN_PLOTS = 3

#: Clutter-estimator name (:data:`mhtrack.names.CLUTTER_ESTIMATORS`) → class.
CLUTTER_ESTIMATOR_CLASSES: dict[str, type[Any]] = dict(
    zip(names.CLUTTER_ESTIMATORS, (KnownClutter, GMMClutter, AGMMClutter), strict=True))


def make_clutter_estimator(name: str, *, kappa: float | None = None,
                           **params: Any) -> ClutterEstimator:
    """A fresh clutter estimator by name (:data:`CLUTTER_ESTIMATOR_CLASSES`). ``kappa`` is
    the constant of ``known`` (default :data:`DEFAULT_CLUTTER_DENSITY`, P1's plain MHT);
    ``params`` go to the mixture estimators' constructors (``None`` values are left at
    their defaults)."""
    if name not in CLUTTER_ESTIMATOR_CLASSES:
        raise ValueError(f"unknown clutter estimator {name!r} "
                         f"(expected {', '.join(CLUTTER_ESTIMATOR_CLASSES)})")
    if name == "known":
        return KnownClutter(DEFAULT_CLUTTER_DENSITY if kappa is None else kappa)
    cls = CLUTTER_ESTIMATOR_CLASSES[name]
    return cls(**{k: v for k, v in params.items() if v is not None})  # type: ignore[no-any-return]


# ---------------------------------------------------------------------- trackers

#: Tracker name (:data:`mhtrack.names.TRACKERS`) → its clutter estimator's name. ``mht``
#: is P1's plain MHT with a known constant clutter intensity; ``mht-gmm`` / ``mht-agmm``
#: estimate it online by a GMM with a fixed deletion threshold / P1's adaptive GMM, each
#: with its defaults and fed all plots (``docs/clutter.md`` says why not
#: ``"outside-gates"``).
TRACKER_ESTIMATORS: dict[str, str] = {"mht": "known", "mht-gmm": "gmm", "mht-agmm": "agmm"}


def takes_clutter_density(tracker: str) -> bool:
    """Whether tracker ``tracker`` assumes a known clutter density (``clutter_density`` of
    :func:`make_tracker`); the others estimate it online and ignore one."""
    return TRACKER_ESTIMATORS.get(tracker) == "known"


def make_tracker(
    name: str,
    config: MHTConfig | None = None,
    *,
    clutter_density: float | None = None,
    birth: str | None = None,
    theta_deg: float | None = None,
    sensors: SensorSet | None = None,
    clutter_frame: str = names.DEFAULT_CLUTTER_FRAME,
    clutter_params: dict[str, Any] | None = None,
) -> MHTTracker:
    """A fresh tracker by name (:data:`TRACKER_ESTIMATORS`).

    ``clutter_density``: the known κ (per m² per scan) of ``mht`` (default
    :data:`DEFAULT_CLUTTER_DENSITY`; ignored by the trackers that estimate it).
    ``birth`` (:data:`mhtrack.names.BIRTHS`) and ``theta_deg`` override ``config.birth`` /
    ``config.birth_theta_deg`` when given.

    ``sensors``: the radars of asynchronous plots (frames of one sensor each,
    :mod:`mhtrack.frames`). The tracker then scores each leaf with the ``P_D`` of the
    frame's radar where its beam swept (:class:`~mhtrack.mht.coverage.RadarCoverage`),
    and estimates clutter per radar, a rotation at a time
    (:class:`~mhtrack.clutter.per_sensor.PerSensorClutter`, the tracker's estimator per
    radar; ``known``: κ per m² per look) — in the radar's own range and bearing
    (``clutter_frame="polar"``, :class:`~mhtrack.clutter.polar.PolarClutter`) or in the
    local plane (``"plane"``) — and confirms a tree only once its branch holds
    at least :data:`TIMED_CONFIRM_MIN_PLOTS` plots (``config.confirm_min_plots`` if
    larger).

    ``clutter_params``: keywords of the tracker's clutter estimator
    (:func:`make_clutter_estimator`; e.g. ``{"bic": False}``); ``known`` ignores them."""
    if name not in TRACKER_ESTIMATORS:
        raise ValueError(f"unknown tracker {name!r} "
                         f"(expected one of {', '.join(TRACKER_ESTIMATORS)})")
    config = config_with(config, birth=birth, birth_theta_deg=theta_deg)
    kappa = clutter_density if takes_clutter_density(name) else None
    estimator = TRACKER_ESTIMATORS[name]
    params = {} if clutter_params is None or estimator == "known" else dict(clutter_params)
    recipe = {"name": name, "clutter_density": clutter_density,
              "clutter_frame": clutter_frame, "clutter_params": params or None,
              "sensors": None if sensors is None else sensors_recipe(sensors)}
    if sensors is None:
        return _with_recipe(MHTTracker(
            config, make_clutter_estimator(estimator, kappa=kappa, **params)), recipe)
    config = config_with(config, confirm_min_plots=max(config.confirm_min_plots,
                                                       TIMED_CONFIRM_MIN_PLOTS))
    if clutter_frame not in names.CLUTTER_FRAMES:
        raise ValueError(f"unknown clutter frame {clutter_frame!r} "
                         f"(expected one of {', '.join(names.CLUTTER_FRAMES)})")
    wrap = None
    if clutter_frame == "polar" and estimator != "known":
        def wrap(sid: int, inner: ClutterEstimator) -> ClutterEstimator:
            s = sensors.sensor(sid)
            return inner if not s.has_site else PolarClutter(inner, sensors.site_xy(sid))
    clutter = PerSensorClutter(
        lambda: make_clutter_estimator(estimator, kappa=kappa, **params),
        {s.id: s.period for s in sensors.sensors},
        initial=DEFAULT_CLUTTER_DENSITY if kappa is None else kappa, wrap=wrap)
    return _with_recipe(MHTTracker(config, clutter, coverage=RadarCoverage(sensors)), recipe)


def _with_recipe(trk: MHTTracker, recipe: dict[str, Any]) -> MHTTracker:
    trk.recipe = recipe
    return trk


def sensors_recipe(sensors: SensorSet) -> dict[str, Any]:
    """``sensors`` as JSON-able values (:func:`sensors_from_recipe` reverses it)."""
    return {"origin": None if sensors.origin is None else list(sensors.origin),
            "sensors": [{k: (list(v) if isinstance(v, tuple) else v)
                         for k, v in dataclasses.asdict(s).items()}
                        for s in sensors.sensors]}


def sensors_from_recipe(d: dict[str, Any]) -> SensorSet:
    """The :class:`SensorSet` of :func:`sensors_recipe`."""
    return SensorSet(None if d["origin"] is None else tuple(d["origin"]), tuple(
        RadarSensor(**{k: (tuple(v) if isinstance(v, list) else v) for k, v in s.items()})
        for s in d["sensors"]))


def load_tracker(path: str | os.PathLike[str]) -> MHTTracker:
    """Restore a tracker that :func:`make_tracker` built and ``save`` wrote, without
    passing its parts again: the state holds the builder's recipe (tracker name, known
    κ, clutter frame and estimator keywords, the radars), from which the clutter
    estimator, motion model, birth process and coverage are rebuilt, then
    :meth:`MHTTracker.load` restores their states. A tracker assembled by hand has no
    recipe: load it with :meth:`MHTTracker.load` and its parts."""
    from mhtrack.mht.state import saved_meta

    meta = saved_meta(path)
    recipe = meta.get("recipe")
    if not isinstance(recipe, dict):
        raise ValueError(f"{path}: saved by a tracker not made by mhtrack.build.make_tracker "
                         "(no recipe): use MHTTracker.load(path, clutter, motion=..., "
                         "birth=..., coverage=...)")
    try:
        sensors = (None if recipe.get("sensors") is None
                   else sensors_from_recipe(recipe["sensors"]))
        fresh = make_tracker(recipe["name"], MHTConfig.from_json(json.dumps(meta["config"])),
                             clutter_density=recipe.get("clutter_density"), sensors=sensors,
                             clutter_frame=recipe.get("clutter_frame", names.DEFAULT_CLUTTER_FRAME),
                             clutter_params=recipe.get("clutter_params"))
    except (KeyError, TypeError, ValueError) as e:
        raise ValueError(f"{path}: member 'meta': field 'recipe' cannot be rebuilt "
                         f"({e})") from None
    trk = MHTTracker.load(path, fresh.clutter, motion=fresh.motion, birth=fresh.birth,
                          coverage=fresh.coverage)
    trk.recipe = recipe
    return trk


# ---------------------------------------------------------------------- defaults

#: New targets per scan that P1's λv = 1e−7 per m² means over P1's 8 km × 8 km region
#: (P1 §3): 6.4. :func:`default_config` keeps this rate and scales the density to the
#: surveillance area at hand, so that P1's value is used on P1's region and a 500 km
#: air-surveillance picture does not expect 29 000 new targets per scan.
P1_BIRTHS_PER_SCAN = 1e-7 * 8000.0**2

#: Largest ``P_D`` the tracker takes from a scenario: a sensor with ``P_D = 1`` would make
#: one missed plot (gating, a plot lost in fusion) cost ``ln 0``; at 0.999 a miss costs
#: ``ln 0.001 ≈ −6.9``, two delete the track (``β = 1e−4``).
MAX_TRACKER_PD = 0.999


def capped_pd(pd: float) -> float:
    """``min(P_D, MAX_TRACKER_PD)``: the detection probability the tracker assumes for
    sensors detecting with ``pd``."""
    return min(pd, MAX_TRACKER_PD)


def birth_density_for_area(area: float) -> float:
    """``λv = 6.4 / A`` per m² per scan: P1's new-target rate over an area of ``A`` m²."""
    if not (np.isfinite(area) and area > 0):
        raise ValueError(f"surveillance area must be finite and > 0, got {area}")
    return P1_BIRTHS_PER_SCAN / area


def default_config(scenario: Scenario | None = None, *, area: float | None = None) -> MHTConfig:
    """The tracker defaults (:class:`MHTConfig`, P1 §3) fitted to what is known of the data.

    * The new-target density is scaled to the surveillance area — the scenario's region,
      or ``area`` (e.g. :func:`plots_area` of a plots file) — by
      :func:`birth_density_for_area`; P1's crossing region gives P1's 1e−7.
    * With a scenario of **one** sensor, the tracker's ``P_D`` is that sensor's
      (:func:`capped_pd`), and with a Cartesian sensor ``σw`` is its ``sigma`` (its plots
      carry no covariance of their own; polar plots do). With several sensors the scans
      are fused first and a fused plot's detection probability is not one sensor's, so
      ``P_D`` stays P1's 0.9. On P1's crossing (``P_D`` 0.9, σ 100 m) nothing changes.
    """
    if scenario is None:
        return MHTConfig() if area is None else MHTConfig(
            new_target_density=birth_density_for_area(area))
    changes: dict[str, Any] = {"new_target_density": birth_density_for_area(
        scenario.region.area)}
    if len(scenario.sensors) == 1:
        changes["p_detection"] = capped_pd(float(scenario.pd[0]))
        sensor = scenario.sensors[0]
        if isinstance(sensor, CartesianSensor):
            changes["sigma_w"] = float(sensor.sigma)
    return MHTConfig(**changes)


def config_with(config: MHTConfig | None = None, **changes: Any) -> MHTConfig:
    """``config`` (default :class:`MHTConfig`) with the non-``None`` ``changes`` applied."""
    config = MHTConfig() if config is None else config
    return dataclasses.replace(config, **{k: v for k, v in changes.items() if v is not None})


#: The surveillance area of plots without a scenario is the box between these quantiles
#: of their x and y (so a few wild plots do not inflate it).
AREA_QUANTILES = (0.005, 0.995)


@dataclass(frozen=True)
class PlotsArea:
    """The robust bounding box of a set of plots (see :func:`plots_area`)."""

    x0: float
    x1: float
    y0: float
    y1: float
    #: Box sides (m), each at least 1 m.
    width: float
    height: float
    #: Plots farther outside the box than its own width (east-west) or height.
    n_far: int

    @property
    def area(self) -> float:
        """``width × height`` (m²)."""
        return self.width * self.height


def plots_area(x: npt.ArrayLike, y: npt.ArrayLike) -> PlotsArea:
    """The box between the :data:`AREA_QUANTILES` (0.5 % and 99.5 %) of the plots' ``x``
    and ``y`` (each side at least 1 m), and how many plots lie farther outside it than
    its width or height — a surveillance area for :func:`default_config` when no scenario
    gives the region."""
    x, y = np.asarray(x), np.asarray(y)
    (x0, x1), (y0, y1) = (np.quantile(v, AREA_QUANTILES) for v in (x, y))
    wx, wy = max(float(x1 - x0), 1.0), max(float(y1 - y0), 1.0)
    with np.errstate(over="ignore", invalid="ignore"):
        far = (x < x0 - wx) | (x > x1 + wx) | (y < y0 - wy) | (y > y1 + wy)
    return PlotsArea(x0, x1, y0, y1, wx, wy, int(np.count_nonzero(far)))


def known_kappa_mismatch(scenario: Scenario,
                         kappa: float = DEFAULT_CLUTTER_DENSITY) -> float | None:
    """The scenario's mean clutter density ``S λ̄ / A`` when it is over 10× ``kappa`` or
    (being > 0) under a tenth of it — a tracker assuming ``kappa`` then scores its plots
    mostly as targets, or its targets as clutter; ``None`` when they are close."""
    mean = scenario.mean_clutter_density()
    if mean > 10 * kappa or 0 < mean < 0.1 * kappa:
        return mean
    return None


# ---------------------------------------------------------------------- fusion

#: How the tracker's fusion combines a cluster's plots: ``"information"``, the maximum-
#: likelihood position of independent Gaussian plots of one point,
#: ``P = (Σ R_i⁻¹)⁻¹``, ``z = P Σ R_i⁻¹ z_i`` (e.g. Bar-Shalom, Willett & Tian 2011), not
#: P2's plain centre, whose error keeps half of the worse radar's cross-range error.
TRACKER_FUSION_WEIGHTING = "information"
#: χ² test probability with which the tracker's fusion splits clusters whose plots cannot
#: be of one point (:func:`~mhtrack.initiation.fusion.split_inconsistent`); the same
#: 0.9999 as the clustering's merge gate. Measured in ``docs/mht.md``, *Fusion*.
TRACKER_FUSION_CONSISTENCY = 0.9999


def tracker_fuser() -> AdaptiveKMeansFusion:
    """The fusion before the tracker: P2's adaptive K-means clustering (P2 §1.2), then
    :data:`TRACKER_FUSION_CONSISTENCY` and :data:`TRACKER_FUSION_WEIGHTING`."""
    return AdaptiveKMeansFusion(weighting=TRACKER_FUSION_WEIGHTING,
                                consistency=TRACKER_FUSION_CONSISTENCY)


#: Tracker fusion name (:data:`mhtrack.names.TRACKER_FUSIONS`) → factory of the fuser
#: (``None``: scans go to the tracker as they are).
TRACKER_FUSERS: dict[str, Callable[[], AdaptiveKMeansFusion] | None] = {
    "none": None, "adaptive-kmeans": tracker_fuser}

#: Fusion name before P2's initiators (:data:`mhtrack.names.INITIATION_FUSIONS`) → class
#: (``None``: no fusion). ``kmeans`` (random initial centres, P2 §1.1) needs its number
#: of clusters.
INITIATION_FUSER_CLASSES: dict[str, type[Any] | None] = {
    "adaptive-kmeans": AdaptiveKMeansFusion, "kmeans": KMeansFusion, "none": None}


def birth_suffix(birth: str | None) -> str:
    """``-BIRTH`` naming a birth process other than the default (every plot), else ``""``
    (the names of run directories)."""
    return "" if birth is None or birth == names.EVERY_PLOT else f"-{birth}"


def default_fusion(n_sensors: int) -> str:
    """The tracker's fusion: ``"adaptive-kmeans"`` with more than one sensor (the MHT
    assumes at most one plot per target per scan), else ``"none"``."""
    return "adaptive-kmeans" if n_sensors > 1 else "none"


__all__ = [
    "AREA_QUANTILES",
    "CLUTTER_ESTIMATOR_CLASSES",
    "DEFAULT_CLUTTER_DENSITY",
    "INITIATION_FUSER_CLASSES",
    "INITIATOR_CLASSES",
    "MAX_TRACKER_PD",
    "P1_BIRTHS_PER_SCAN",
    "TRACKER_ESTIMATORS",
    "TRACKER_FUSERS",
    "TRACKER_FUSION_CONSISTENCY",
    "TRACKER_FUSION_WEIGHTING",
    "PlotsArea",
    "birth_density_for_area",
    "capped_pd",
    "config_with",
    "default_config",
    "default_fusion",
    "known_kappa_mismatch",
    "make_clutter_estimator",
    "make_initiator",
    "make_tracker",
    "plots_area",
    "takes_clutter_density",
    "tracker_fuser",
]
