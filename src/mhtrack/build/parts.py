"""Every part by its name: the one table per kind of part from the names of
:mod:`mhtrack.names` to the classes or factories, and the functions that build them.

* trackers (:data:`~mhtrack.names.TRACKERS`) → the clutter estimator each one runs
  (:data:`TRACKER_ESTIMATORS`), built by :func:`make_tracker`;
* clutter estimators (:data:`~mhtrack.names.CLUTTER_ESTIMATORS`) →
  :data:`CLUTTER_ESTIMATOR_CLASSES`, built by :func:`make_clutter_estimator`;
* births (:data:`~mhtrack.names.BIRTHS`) → :data:`BIRTH_FACTORIES`, built by
  :func:`make_birth`;
* initiators (:data:`~mhtrack.names.INITIATORS`) →
  :data:`~mhtrack.initiation.factory.INITIATOR_CLASSES` (kept beside the initiators,
  layer 3, because the MHT's initiator birth builds one per window), built by
  :func:`make_initiator`;
* plot fusions (:data:`~mhtrack.names.TRACKER_FUSIONS`,
  :data:`~mhtrack.names.INITIATION_FUSIONS`) → :data:`TRACKER_FUSERS`,
  :data:`INITIATION_FUSER_CLASSES`.

Nothing outside this module branches on a part's name.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from typing import Any

from mhtrack import names
from mhtrack.build.defaults import DEFAULT_CLUTTER_DENSITY, config_with
from mhtrack.build.recipe import sensors_from_recipe, sensors_recipe
from mhtrack.clutter.agmm import AGMMClutter
from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.calibrated import MapCalibratedClutter
from mhtrack.clutter.forgetting import ForgettingGMMClutter
from mhtrack.clutter.gmm import GMMClutter
from mhtrack.clutter.known import KnownClutter
from mhtrack.clutter.per_sensor import PerSensorClutter
from mhtrack.clutter.polar import PolarClutter
from mhtrack.clutter.radar_map import ClutterMap
from mhtrack.initiation.fusion import AdaptiveKMeansFusion, KMeansFusion
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.mht.births import Birth, InitiatorBirth, TimedInitiatorBirth, default_birth
from mhtrack.mht.births.clutter_scaled import ClutterScaledBirth
from mhtrack.mht.coverage import Coverage, Everywhere, RadarCoverage
from mhtrack.mht.gating import gate_threshold
from mhtrack.mht.scoring import miss_increment
from mhtrack.mht.sprt import sprt_thresholds
from mhtrack.models.motion import MotionModel
from mhtrack.models.radars import SensorSet
from mhtrack.records import Scan

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
    zip(names.CLUTTER_ESTIMATORS, (KnownClutter, GMMClutter, AGMMClutter, ClutterMap,
                                   ForgettingGMMClutter, MapCalibratedClutter), strict=True))


def make_clutter_estimator(name: str, *, kappa: float | None = None,
                           **params: Any) -> ClutterEstimator:
    """A fresh clutter estimator by name (:data:`CLUTTER_ESTIMATOR_CLASSES`). ``kappa`` is
    the constant of ``known`` (default :data:`DEFAULT_CLUTTER_DENSITY`, P1's plain MHT);
    ``params`` go to the other estimators' constructors (``None`` values are left at
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
TRACKER_ESTIMATORS: dict[str, str] = {"mht": "known", "mht-gmm": "gmm", "mht-agmm": "agmm",
                                      "mht-map": "map", "mht-fgmm": "fgmm",
                                      "mht-mapgmm": "mapgmm"}


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
    (:func:`make_clutter_estimator`; e.g. ``{"bic": False}``); ``known`` ignores them.
    ``mht-map``'s clutter map is about each radar's own site, rings out to its
    ``max_range``, whatever ``clutter_frame``; its ``birth_scaling`` β > 0 wraps the birth
    process in :class:`~mhtrack.mht.births.clutter_scaled.ClutterScaledBirth`."""
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
        return _assemble(config, make_clutter_estimator(estimator, kappa=kappa, **params),
                         Everywhere(config.p_detection), recipe)
    periods = {s.id: s.period for s in sensors.sensors}
    config = config_with(config, confirm_min_plots=max(config.confirm_min_plots,
                                                       TIMED_CONFIRM_MIN_PLOTS))
    clutter = radar_clutter(estimator, sensors, kappa=kappa, params=params,
                            clutter_frame=clutter_frame)
    return _assemble(config, clutter, RadarCoverage(sensors), recipe, periods)


def radar_clutter(estimator: str, sensors: SensorSet, *, kappa: float | None = None,
                  params: dict[str, Any] | None = None,
                  clutter_frame: str = names.DEFAULT_CLUTTER_FRAME) -> PerSensorClutter:
    """The clutter estimator of timed plots (:func:`make_tracker` with ``sensors``): one
    ``estimator`` (:func:`make_clutter_estimator`, with ``kappa`` and ``params``) per
    radar, fed a rotation at a time, in the radar's range and bearing
    (``clutter_frame="polar"``, radars with a site; ``known`` is never wrapped) or in the
    local plane (``"plane"``); ``kappa`` (default :data:`DEFAULT_CLUTTER_DENSITY`) before
    a radar's first rotation."""
    if clutter_frame not in names.CLUTTER_FRAMES:
        raise ValueError(f"unknown clutter frame {clutter_frame!r} "
                         f"(expected one of {', '.join(names.CLUTTER_FRAMES)})")
    kw = dict(params or {})
    wrap = None
    if estimator == "map":  # a range–azimuth map about each radar's own site, any frame
        def wrap(sid: int, inner: ClutterEstimator) -> ClutterEstimator:
            s = sensors.sensor(sid)
            return inner.placed(sensors.site_xy(sid) if s.has_site else (0.0, 0.0),
                                s.max_range)  # type: ignore[attr-defined]
    elif estimator == "mapgmm":  # the map about the site; its GMM in the clutter frame
        def wrap(sid: int, inner: ClutterEstimator) -> ClutterEstimator:
            s = sensors.sensor(sid)
            site = sensors.site_xy(sid) if s.has_site else (0.0, 0.0)
            base = GMMClutter(**inner.base_params)  # type: ignore[attr-defined]
            if clutter_frame == "polar" and s.has_site:
                base = PolarClutter(base, site)  # type: ignore[assignment]
            return inner.placed(site, s.max_range, base)  # type: ignore[attr-defined]
    elif clutter_frame == "polar" and estimator != "known":
        def wrap(sid: int, inner: ClutterEstimator) -> ClutterEstimator:
            s = sensors.sensor(sid)
            return inner if not s.has_site else PolarClutter(inner, sensors.site_xy(sid))
    return PerSensorClutter(
        lambda: make_clutter_estimator(estimator, kappa=kappa, **kw),
        {s.id: s.period for s in sensors.sensors},
        initial=DEFAULT_CLUTTER_DENSITY if kappa is None else kappa, wrap=wrap)


def _assemble(config: MHTConfig, clutter: ClutterEstimator, coverage: Coverage,
              recipe: dict[str, Any], periods: dict[int, float | None] | None = None
              ) -> MHTTracker:
    """The tracker of ``config`` with its parts: the configuration's motion model, the
    birth ``config.birth`` names (:func:`make_birth`, scored with the coverage's
    ``P_D``; ``periods`` of timed plots' radars), and the builder's ``recipe``."""
    motion = config.motion
    birth = make_birth(config, motion, coverage.plot_pd, periods)
    beta = (recipe.get("clutter_params") or {}).get("birth_scaling")
    if beta:  # the clutter map drives the birth density (mhtrack.mht.births.clutter_scaled)
        birth = ClutterScaledBirth(birth, clutter, float(beta))
    trk = MHTTracker(config, clutter, motion=motion, coverage=coverage, birth=birth)
    trk.recipe = recipe
    return trk


# ------------------------------------------------------------------------ births

def _initiator_birth(method: str) -> Callable[..., Birth]:
    """The birth of P2's initiator ``method`` over the last scans (:class:`InitiatorBirth`),
    or, with the radars' ``periods`` (timed plots), over each radar's last rotations
    (:class:`TimedInitiatorBirth`, the logic's χ² gate at the tracker's ``P_G``)."""
    def make(cfg: MHTConfig, motion: MotionModel,
             plot_pd: Callable[[Scan], float] | None,
             periods: dict[int, float | None] | None = None) -> Birth:
        pg = cfg.gate_probability if cfg.miss_uses_gate_probability else None
        params = dict(
            theta_deg=cfg.birth_theta_deg, width=cfg.n_scan + 1,
            p_detection=cfg.p_detection, new_target_density=cfg.new_target_density,
            miss_dl=miss_increment(cfg.p_detection, pg),
            v_max=cfg.v_max, floor=sprt_thresholds(cfg.alpha, cfg.beta)[1],
            max_per_scan=cfg.max_births_per_scan, prune_drop=cfg.prune_drop,
            max_leaves_per_tree=cfg.max_leaves_per_tree)
        if periods is None:
            return InitiatorBirth(method, motion, **params)
        return TimedInitiatorBirth(
            method, motion, periods=periods,
            plot_pd=plot_pd if plot_pd is not None else lambda scan: cfg.p_detection,
            gate_probability=pg, gate_chi2=gate_threshold(cfg.gate_probability), **params)
    return make


#: Birth name (:data:`mhtrack.names.BIRTHS`) → factory ``(config, motion, plot_pd) → Birth``.
BIRTH_FACTORIES: dict[str, Callable[..., Birth]] = {
    names.EVERY_PLOT: default_birth, **{m: _initiator_birth(m) for m in names.INITIATORS}}


def make_birth(cfg: MHTConfig, motion: MotionModel,
               plot_pd: Callable[[Scan], float] | None = None,
               periods: dict[int, float | None] | None = None) -> Birth:
    """The birth process ``cfg.birth`` (:data:`BIRTH_FACTORIES`) with the configuration's
    parameters; new trees start only above the SPRT deletion threshold ``ln(β/(1−α))``.
    ``plot_pd``: the ``P_D`` of a scan's sensor for the birth score (``None``:
    ``cfg.p_detection``). ``periods``: rotation period per sensor id of timed plots
    (frames of one sensor each); P2's initiators then work on each radar's rotations."""
    if cfg.birth not in BIRTH_FACTORIES:
        raise ValueError(f"unknown birth {cfg.birth!r} "
                         f"(expected one of {', '.join(BIRTH_FACTORIES)})")
    if periods is not None and cfg.birth != names.EVERY_PLOT:
        return BIRTH_FACTORIES[cfg.birth](cfg, motion, plot_pd, periods)
    return BIRTH_FACTORIES[cfg.birth](cfg, motion, plot_pd)


def load_tracker(path: str | os.PathLike[str]) -> MHTTracker:
    """Restore a tracker that :func:`make_tracker` built and ``save`` wrote, without
    passing its parts again: the state holds the builder's recipe (tracker name, known
    κ, clutter frame and estimator keywords, the radars), from which the clutter
    estimator, motion model, birth process and coverage are rebuilt, then
    :meth:`MHTTracker.load` restores their states. A tracker assembled by hand has no
    recipe: load it with :meth:`MHTTracker.load` and its parts."""
    from mhtrack.io.npzfile import member_error
    from mhtrack.mht.state import saved_meta

    meta = saved_meta(path)
    recipe = meta.get("recipe")
    if not isinstance(recipe, dict):  # absent (assembled by hand) or damaged
        raise member_error(path, "meta", "saved by a tracker not made by "
                           "mhtrack.build.make_tracker (no recipe): use MHTTracker.load("
                           "path, clutter, motion=..., birth=..., coverage=...)")
    try:
        sensors = (None if recipe.get("sensors") is None
                   else sensors_from_recipe(recipe["sensors"]))
        fresh = make_tracker(recipe["name"], MHTConfig.from_json(json.dumps(meta["config"])),
                             clutter_density=recipe.get("clutter_density"), sensors=sensors,
                             clutter_frame=recipe.get("clutter_frame", names.DEFAULT_CLUTTER_FRAME),
                             clutter_params=recipe.get("clutter_params"))
    except (KeyError, TypeError, ValueError, OverflowError) as e:
        raise member_error(path, "meta", f"field 'recipe' cannot be rebuilt ({e})") from None
    trk = MHTTracker.load(path, fresh.clutter, motion=fresh.motion, birth=fresh.birth,
                          coverage=fresh.coverage)
    trk.recipe = recipe
    return trk


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


