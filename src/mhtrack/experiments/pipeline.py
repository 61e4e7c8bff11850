"""One tracking run: build a tracker by name, feed it scans, time it, score it.

The CLI's ``track`` and ``run`` and the Monte-Carlo runner all go through here, so a
tracker is configured, timed and evaluated the same way everywhere.

Birth process (``birth``, ``theta_deg``): which plots start new track trees
(``MHTConfig.birth``, ``docs/mht.md``). Fusion (``fusion``): the MHT assumes at most one
plot per target per scan, so with several sensors each scan is first fused by
:class:`~mhtrack.initiation.AdaptiveKMeansFusion` (P2 §1.2) — the default when the scenario
has more than one sensor (:func:`default_fusion`) — with a χ² consistency split and
information weighting (:func:`tracker_fuser`). A fused plot's row id (the ``plot``
column of the tracks) is the plot-table row of the first plot of its cluster (in scan
order), so it stays a valid plot-table row.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
from tqdm.auto import tqdm

from mhtrack.clutter import ClutterEstimator, KnownClutter
from mhtrack.clutter.registry import agmm_for_tracker, gmm_for_tracker
from mhtrack.initiation import AdaptiveKMeansFusion
from mhtrack.metrics import Evaluation, evaluate
from mhtrack.mht import MHTConfig, MHTTracker, StepStats
from mhtrack.models.sensors import CartesianSensor
from mhtrack.records import PlotTable, Scan, TrackTable
from mhtrack.scenario import Scenario, Simulation, simulate

#: Default known clutter density of the plain MHT (P1 §3: 1e−9 per m²).
DEFAULT_CLUTTER_DENSITY = 1e-9


def _known(config: MHTConfig, clutter_density: float | None) -> ClutterEstimator:
    return KnownClutter(DEFAULT_CLUTTER_DENSITY if clutter_density is None else clutter_density)


#: Tracker name → factory of its clutter estimator. ``mht`` is P1's plain MHT with a known
#: constant clutter intensity; ``mht-gmm`` / ``mht-agmm`` estimate it online by a GMM with a
#: fixed deletion threshold / P1's adaptive GMM (``docs/clutter.md``).
TRACKERS: dict[str, Callable[[MHTConfig, float | None], ClutterEstimator]] = {
    "mht": _known,
    "mht-gmm": gmm_for_tracker,
    "mht-agmm": agmm_for_tracker,
}


#: Plot fusion methods of :func:`track` / :func:`run_scenario`.
FUSIONS: tuple[str, ...] = ("none", "adaptive-kmeans")


def make_tracker(
    name: str,
    config: MHTConfig | None = None,
    *,
    clutter_density: float | None = None,
    birth: str | None = None,
    theta_deg: float | None = None,
) -> MHTTracker:
    """A fresh tracker by name (see :data:`TRACKERS`). ``birth`` (``"every-plot"``,
    ``"logic"``, ``"modified-logic"``, ``"hough"``, ``"modified-hough"``) and ``theta_deg``
    override ``config.birth`` / ``config.birth_theta_deg`` when given."""
    if name not in TRACKERS:
        raise ValueError(f"unknown tracker {name!r} (expected one of {', '.join(TRACKERS)})")
    config = config_with(config, birth=birth, birth_theta_deg=theta_deg)
    return MHTTracker(config, TRACKERS[name](config, clutter_density))


def default_fusion(n_sensors: int) -> str:
    """``"adaptive-kmeans"`` with more than one sensor, else ``"none"``."""
    return "adaptive-kmeans" if n_sensors > 1 else "none"


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
    """The fusion the tracker's pipeline uses: P2's adaptive K-means clustering, then
    :data:`TRACKER_FUSION_CONSISTENCY` and :data:`TRACKER_FUSION_WEIGHTING`."""
    return AdaptiveKMeansFusion(weighting=TRACKER_FUSION_WEIGHTING,
                                consistency=TRACKER_FUSION_CONSISTENCY)


def fuse_scan(scan: Scan, fuser: AdaptiveKMeansFusion | None = None) -> Scan:
    """``scan`` fused by adaptive K-means (P2 §1.2): one plot per cluster, with its fused
    ``R`` and, as row id, the row of the cluster's first plot (module docstring). Default
    ``fuser``: :func:`tracker_fuser`."""
    if len(scan) == 0:
        return scan
    f = (tracker_fuser() if fuser is None else fuser).fuse(scan)
    k = len(f.scan)
    first = np.full(k, -1, np.int64)
    first[f.labels[::-1]] = np.arange(len(f.labels))[::-1]
    return dataclasses.replace(f.scan, rows=np.asarray(scan.rows, np.int64)[first])


def fused(scans: Iterable[Scan], fusion: str) -> Iterable[Scan]:
    """``scans`` unchanged (``"none"``) or each fused (``"adaptive-kmeans"``)."""
    if fusion not in FUSIONS:
        raise ValueError(f"unknown fusion {fusion!r} (expected {', '.join(FUSIONS)})")
    if fusion == "none":
        return scans
    fuser = tracker_fuser()
    return (fuse_scan(s, fuser) for s in scans)


@dataclass(frozen=True)
class TrackingRun:
    """Output of a tracker over a sequence of scans, with its per-scan statistics."""

    tracker: str
    tracks: TrackTable
    stats: tuple[StepStats, ...]
    output: str = "history"

    @property
    def seconds_per_scan(self) -> np.ndarray:
        return np.array([s.time_s for s in self.stats])

    @property
    def t_avg(self) -> float:
        """Mean tracker time per scan (s) — P1 Table 3's ``Tavg``."""
        t = self.seconds_per_scan
        return float(t.mean()) if t.size else 0.0

    @property
    def caps(self) -> dict[str, int]:
        """Total of every hard cap that acted, over the run."""
        total: dict[str, int] = {}
        for s in self.stats:
            for k, v in s.caps.items():
                total[k] = total.get(k, 0) + v
        return total


#: Output modes of a batch run: ``"history"`` — every confirmed track also at the scans
#: before its confirmation (its tentative past, back to its first plot within
#: ``MHTConfig.history_scans``, rows marked ``tentative``; :mod:`mhtrack.mht.history`);
#: ``"online"`` — only what each step reported at its scan.
OUTPUTS = ("history", "online")


def track(
    tracker: MHTTracker, scans: PlotTable | Iterable[Scan], *, name: str = "mht",
    progress: bool = False, fusion: str = "none", output: str = "history",
) -> TrackingRun:
    """Run ``tracker`` over ``scans`` (a :class:`PlotTable` or scans), one step per scan;
    with ``fusion="adaptive-kmeans"`` each scan is fused first (module docstring).
    ``output``: one of :data:`OUTPUTS`."""
    if output not in OUTPUTS:
        raise ValueError(f"unknown output {output!r} (expected one of {', '.join(OUTPUTS)})")
    total = None
    if isinstance(scans, PlotTable):
        total = scans.n_scans
        scans = scans.scans()
    stats: list[StepStats] = []
    bar = tqdm(fused(scans, fusion), total=total, desc=name, unit="scan",
               disable=not progress, leave=False)
    tracks = tracker.run(bar, stats, history=output == "history")
    return TrackingRun(name, tracks, tuple(stats), output)


@dataclass(frozen=True)
class ScenarioRun:
    """Simulate → track → evaluate, all of one run."""

    simulation: Simulation
    run: TrackingRun
    evaluation: Evaluation

    def summary(self) -> dict[str, Any]:
        """The ``evaluate`` JSON object plus ``t_avg`` (s/scan), ``tracker``, ``caps`` and
        ``output`` (the output mode, :data:`OUTPUTS`)."""
        return {
            **self.evaluation.to_dict(),
            "t_avg": self.run.t_avg,
            "tracker": self.run.tracker,
            "caps": self.run.caps,
            "output": self.run.output,
        }


def run_scenario(
    scenario: Scenario,
    seed: int,
    tracker: str = "mht",
    config: MHTConfig | None = None,
    *,
    clutter_density: float | None = None,
    cutoff: float = 500.0,
    order: float = 2.0,
    progress: bool = False,
    birth: str | None = None,
    theta_deg: float | None = None,
    fusion: str | None = None,
    output: str = "history",
) -> ScenarioRun:
    """Simulate ``scenario`` with ``seed``, run tracker ``tracker`` on it and evaluate.

    ``birth`` / ``theta_deg``: see :func:`make_tracker`; ``fusion``: ``"none"`` or
    ``"adaptive-kmeans"``, default :func:`default_fusion` of the scenario's sensors;
    ``output``: see :func:`track`."""
    sim = simulate(scenario, seed=seed)
    config = default_config(scenario) if config is None else config
    trk = make_tracker(tracker, config, clutter_density=clutter_density, birth=birth,
                       theta_deg=theta_deg)
    if fusion is None:
        fusion = default_fusion(len(scenario.sensors))
    run = track(trk, sim.plots, name=tracker, progress=progress, fusion=fusion, output=output)
    ev = evaluate(run.tracks, sim.truth, plots=sim.plots, cutoff=cutoff, order=order)
    return ScenarioRun(sim, run, ev)


#: New targets per scan that P1's λv = 1e−7 per m² means over P1's 8 km × 8 km region
#: (P1 §3): 6.4. :func:`default_config` keeps this rate and scales the density to the
#: surveillance area at hand, so that P1's value is used on P1's region and a 500 km
#: air-surveillance picture does not expect 29 000 new targets per scan.
P1_BIRTHS_PER_SCAN = 1e-7 * 8000.0**2


#: Largest ``P_D`` :func:`default_config` takes from a scenario: a sensor with ``P_D = 1``
#: would make one missed plot (gating, a plot lost in fusion) cost ``ln 0``; at 0.999 a
#: miss costs ``ln 0.001 ≈ −6.9``, two delete the track (``β = 1e−4``).
MAX_TRACKER_PD = 0.999


def birth_density_for_area(area: float) -> float:
    """``λv = 6.4 / A`` per m² per scan: P1's new-target rate over an area of ``A`` m²."""
    if not (np.isfinite(area) and area > 0):
        raise ValueError(f"surveillance area must be finite and > 0, got {area}")
    return P1_BIRTHS_PER_SCAN / area


def default_config(scenario: Scenario | None = None, *, area: float | None = None) -> MHTConfig:
    """The tracker defaults (:class:`MHTConfig`, P1 §3) fitted to what is known of the data.

    * The new-target density is scaled to the surveillance area — the scenario's region,
      or ``area`` (e.g. the bounding box of a plots file) — by
      :func:`birth_density_for_area`; P1's crossing region gives P1's 1e−7.
    * With a scenario of **one** sensor, the tracker's ``P_D`` is that sensor's (at most
      :data:`MAX_TRACKER_PD`), and with a Cartesian sensor ``σw`` is its ``sigma`` (its
      plots carry no covariance of their own; polar plots do). With several sensors the
      scans are fused first and a fused plot's detection probability is not one sensor's,
      so ``P_D`` stays P1's 0.9. On P1's crossing (``P_D`` 0.9, σ 100 m) nothing changes.
    """
    if scenario is None:
        return MHTConfig() if area is None else MHTConfig(
            new_target_density=birth_density_for_area(area))
    changes: dict[str, Any] = {"new_target_density": birth_density_for_area(
        scenario.region.area)}
    if len(scenario.sensors) == 1:
        changes["p_detection"] = min(float(scenario.pd[0]), MAX_TRACKER_PD)
        sensor = scenario.sensors[0]
        if isinstance(sensor, CartesianSensor):
            changes["sigma_w"] = float(sensor.sigma)
    return MHTConfig(**changes)


def config_with(config: MHTConfig | None = None, **changes: Any) -> MHTConfig:
    """``config`` (default :class:`MHTConfig`) with the non-``None`` ``changes`` applied."""
    config = MHTConfig() if config is None else config
    return dataclasses.replace(config, **{k: v for k, v in changes.items() if v is not None})
