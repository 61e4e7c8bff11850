"""One tracking run: build a tracker by name, feed it scans, time it, score it.

The CLI's ``track`` and ``run`` and the Monte-Carlo runner all go through here, so a
tracker is configured, timed and evaluated the same way everywhere.
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
from mhtrack.metrics import Evaluation, evaluate
from mhtrack.mht import MHTConfig, MHTTracker, StepStats
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


def make_tracker(
    name: str, config: MHTConfig | None = None, *, clutter_density: float | None = None
) -> MHTTracker:
    """A fresh tracker by name (see :data:`TRACKERS`)."""
    if name not in TRACKERS:
        raise ValueError(f"unknown tracker {name!r} (expected one of {', '.join(TRACKERS)})")
    config = MHTConfig() if config is None else config
    return MHTTracker(config, TRACKERS[name](config, clutter_density))


@dataclass(frozen=True)
class TrackingRun:
    """Output of a tracker over a sequence of scans, with its per-scan statistics."""

    tracker: str
    tracks: TrackTable
    stats: tuple[StepStats, ...]

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


def track(
    tracker: MHTTracker, scans: PlotTable | Iterable[Scan], *, name: str = "mht",
    progress: bool = False,
) -> TrackingRun:
    """Run ``tracker`` over ``scans`` (a :class:`PlotTable` or scans), one step per scan."""
    total = None
    if isinstance(scans, PlotTable):
        total = scans.n_scans
        scans = scans.scans()
    parts: list[TrackTable] = []
    stats: list[StepStats] = []
    for scan in tqdm(scans, total=total, desc=name, unit="scan", disable=not progress,
                     leave=False):
        parts.append(tracker.step(scan))
        assert tracker.last_stats is not None
        stats.append(tracker.last_stats)
    return TrackingRun(name, TrackTable.concat(parts), tuple(stats))


@dataclass(frozen=True)
class ScenarioRun:
    """Simulate → track → evaluate, all of one run."""

    simulation: Simulation
    run: TrackingRun
    evaluation: Evaluation

    def summary(self) -> dict[str, Any]:
        """The ``evaluate`` JSON object plus ``t_avg`` (s/scan), ``tracker`` and ``caps``."""
        return {
            **self.evaluation.to_dict(),
            "t_avg": self.run.t_avg,
            "tracker": self.run.tracker,
            "caps": self.run.caps,
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
) -> ScenarioRun:
    """Simulate ``scenario`` with ``seed``, run tracker ``tracker`` on it and evaluate."""
    sim = simulate(scenario, seed=seed)
    trk = make_tracker(tracker, config, clutter_density=clutter_density)
    run = track(trk, sim.plots, name=tracker, progress=progress)
    ev = evaluate(run.tracks, sim.truth, plots=sim.plots, cutoff=cutoff, order=order)
    return ScenarioRun(sim, run, ev)


def config_with(config: MHTConfig | None = None, **changes: Any) -> MHTConfig:
    """``config`` (default :class:`MHTConfig`) with the non-``None`` ``changes`` applied."""
    config = MHTConfig() if config is None else config
    return dataclasses.replace(config, **{k: v for k, v in changes.items() if v is not None})
