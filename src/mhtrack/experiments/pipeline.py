"""One tracking run: feed a tracker scans, time it, score it (the tracker itself comes
from the builder, :mod:`mhtrack.build`).

The CLI's ``track`` and ``run`` and the Monte-Carlo runner all go through here, so a
tracker is run, timed and evaluated the same way everywhere.

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
from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from tqdm.auto import tqdm

from mhtrack.build import (
    TRACKER_FUSERS,
    default_config,
    default_fusion,
    make_tracker,
    tracker_fuser,
)
from mhtrack.initiation.fusion import AdaptiveKMeansFusion
from mhtrack.mht import MHTConfig, MHTTracker, StepStats
from mhtrack.models.radars import SensorSet
from mhtrack.names import OUTPUTS, TRACKER_FUSIONS
from mhtrack.records import PlotTable, Scan, TrackTable

if TYPE_CHECKING:  # loaded by run_scenario only (fast start of `mhtrack track`)
    from mhtrack.metrics import Evaluation
    from mhtrack.scenario import Scenario, Simulation


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


def fused(scans: Iterable[Scan], fusion: str,
          caps: dict[int, dict[str, int]] | None = None) -> Iterable[Scan]:
    """``scans`` unchanged (``"none"``) or each fused (``"adaptive-kmeans"``). The caps
    the fusion applied in a burst (``Fuser.caps_``, logged by ``Fuser.fuse``) go to
    ``caps[scan index]``."""
    if fusion not in TRACKER_FUSIONS:
        raise ValueError(f"unknown fusion {fusion!r} (expected {', '.join(TRACKER_FUSIONS)})")
    factory = TRACKER_FUSERS[fusion]
    if factory is None:
        return scans
    fuser = factory()

    def each(s: Scan) -> Scan:
        out = fuse_scan(s, fuser)  # logs the caps that acted (Fuser.fuse)
        acted = dict(getattr(fuser, "caps_", None) or {}) if len(s) else {}
        if acted and caps is not None:
            caps[int(s.index)] = acted
        return out

    return (each(s) for s in scans)


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
        """Total of every hard cap that acted, over the run, and under ``"scans"`` the
        number of scans (frames) on which any acted; empty when none acted."""
        total: dict[str, int] = {}
        for s in self.stats:
            for k, v in s.caps.items():
                total[k] = total.get(k, 0) + v
        if total:
            total["scans"] = sum(1 for s in self.stats if s.caps)
        return total

    @property
    def cap_scans(self) -> dict[str, list[int]]:
        """The scans at which each hard cap acted (``StepStats.caps``; with the fusion's
        caps, ``fusion_*``, of each scan)."""
        out: dict[str, list[int]] = {}
        for s in self.stats:
            for k in sorted(s.caps):
                out.setdefault(k, []).append(s.scan)
        return out


def track(
    tracker: MHTTracker | str, scans: PlotTable | Iterable[Scan], *, name: str = "mht",
    progress: bool = False, fusion: str = "none", output: str = "history",
    sensors: SensorSet | None = None, config: MHTConfig | None = None,
) -> TrackingRun:
    """Run ``tracker`` over ``scans`` (a :class:`PlotTable` or scans), one step per scan;
    with ``fusion="adaptive-kmeans"`` each scan is fused first (module docstring).
    ``output``: one of :data:`OUTPUTS`.

    A timed table (``PlotTable.timed``: plots with their own times, several radars) is
    stepped frame by frame, unfused. ``tracker`` may be a tracker name; it is then built
    by :func:`~mhtrack.build.make_tracker` with ``config`` and ``sensors`` (the radars'
    coverage and per-radar clutter)."""
    if output not in OUTPUTS:
        raise ValueError(f"unknown output {output!r} (expected one of {', '.join(OUTPUTS)})")
    if isinstance(tracker, str):
        name, tracker = tracker, make_tracker(tracker, config, sensors=sensors)
    if isinstance(scans, PlotTable) and scans.timed and fusion != "none":
        raise ValueError("plots with their own times are tracked frame by frame, one "
                         f"sensor per frame: use fusion 'none', not {fusion!r}")
    total = None
    if isinstance(scans, PlotTable):
        total = scans.n_scans
        scans = scans.scans()
    stats: list[StepStats] = []
    fusion_caps: dict[int, dict[str, int]] = {}
    bar = tqdm(fused(scans, fusion, fusion_caps), total=total, desc=name, unit="scan",
               disable=not progress, leave=False)
    tracks = tracker.run(bar, stats, history=output == "history")
    for st in stats:  # the fusion's caps join the scan's own
        st.caps.update(fusion_caps.get(st.scan, {}))
    return TrackingRun(name, tracks, tuple(stats), output)


@dataclass(frozen=True)
class ScenarioRun:
    """Simulate → track → evaluate, all of one run."""

    simulation: Simulation
    run: TrackingRun
    evaluation: Evaluation

    def summary(self) -> dict[str, Any]:
        """The ``evaluate`` JSON object plus ``t_avg`` (s/scan), ``tracker``, ``caps`` (the
        total each hard cap cut), ``output`` (the output mode, :data:`OUTPUTS`) and, when a
        cap acted, ``cap_scans`` (the scans at which each did)."""
        return {
            **self.evaluation.to_dict(),
            "t_avg": self.run.t_avg,
            "tracker": self.run.tracker,
            "caps": self.run.caps,
            "output": self.run.output,
            # when a cap acted: at which scans (absent otherwise, as on every preset)
            **({"cap_scans": self.run.cap_scans} if self.run.caps else {}),
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
    clutter_params: dict[str, Any] | None = None,
) -> ScenarioRun:
    """Simulate ``scenario`` with ``seed``, run tracker ``tracker`` on it and evaluate.

    ``birth`` / ``theta_deg``: see :func:`make_tracker`; ``fusion``: ``"none"`` or
    ``"adaptive-kmeans"``, default :func:`default_fusion` of the scenario's sensors;
    ``output``: see :func:`track`; ``clutter_params``: keywords of the clutter estimator
    (:func:`make_tracker`). A scenario of rotating radars (plots with their own
    times) is tracked as ``mhtrack track --sensors`` tracks it: frame by frame, unfused,
    with the radars' coverage and per-radar clutter."""
    from mhtrack.metrics import evaluate
    from mhtrack.scenario import simulate

    sim = simulate(scenario, seed=seed)
    config = default_config(scenario) if config is None else config
    timed = sim.plots.timed
    trk = make_tracker(tracker, config, clutter_density=clutter_density, birth=birth,
                       theta_deg=theta_deg, clutter_params=clutter_params,
                       sensors=scenario.sensor_set() if timed else None)
    if fusion is None:
        fusion = "none" if timed else default_fusion(len(scenario.sensors))
    run = track(trk, sim.plots, name=tracker, progress=progress, fusion=fusion, output=output)
    ev = evaluate(run.tracks, sim.truth, plots=sim.plots, cutoff=cutoff, order=order)
    return ScenarioRun(sim, run, ev)


