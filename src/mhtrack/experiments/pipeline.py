"""One tracking run: feed a tracker scans, time it, score it — through the library's one
pipeline (:mod:`mhtrack.pipeline`: source → frames → tracker → sinks), so that a tracker
is run, timed and evaluated the same way by the CLI's ``track`` and ``run`` and by the
Monte-Carlo runner.

The fusion of several sensors' scans and the row ids of fused plots are
:mod:`mhtrack.pipeline`'s (:func:`~mhtrack.pipeline.fuse_scan`,
:func:`~mhtrack.pipeline.fused`).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from mhtrack.build import TRACKER_FUSERS, make_tracker
from mhtrack.mht import MHTConfig, MHTTracker, StepStats
from mhtrack.models.radars import SensorSet
from mhtrack.names import OUTPUTS
from mhtrack.pipeline import (
    Pipeline,
    TrackOptions,
    cap_scans,
    caps_acted,
    feed,
    mean_step_time,
    step_frames,
)
from mhtrack.records import PlotTable, Scan, TrackTable
from mhtrack.sinks import Sink, TrackCollector
from mhtrack.sinks.smoothed import SmoothedHistory
from mhtrack.sources.memory import MemorySource

if TYPE_CHECKING:  # loaded by run_scenario only (fast start of `mhtrack track`)
    from mhtrack.metrics import Evaluation
    from mhtrack.scenario import Scenario, Simulation
    from mhtrack.scenario.identity import AttributeOptions

__all__ = ["ScenarioRun", "TrackingRun", "run_scenario", "track"]


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
        return mean_step_time(self.stats)

    @property
    def caps(self) -> dict[str, int]:
        """Total of every hard cap that acted, over the run, and under ``"scans"`` the
        number of scans (frames) on which any acted; empty when none acted."""
        return caps_acted(self.stats)

    @property
    def cap_scans(self) -> dict[str, list[int]]:
        """The scans at which each hard cap acted (``StepStats.caps``; with the fusion's
        caps, ``fusion_*``, of each scan)."""
        return cap_scans(self.stats)


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
    if isinstance(scans, PlotTable) and scans.timed and TRACKER_FUSERS.get(fusion):
        raise ValueError("plots with their own times are tracked frame by frame, one "
                         f"sensor per frame: use fusion 'none', not {fusion!r}")
    total = None
    if isinstance(scans, PlotTable):
        total = scans.n_scans
        scans = MemorySource(scans)
    rows = TrackCollector(output)
    sinks: list[Sink] = [rows]
    if output == "smoothed":
        tracker.keep_models = True
        sinks = [SmoothedHistory(sinks, tracker.motion)]
    stats, _ = feed(step_frames(tracker, scans, fusion=fusion, name=name, progress=progress,
                                total=total), sinks)
    return TrackingRun(name, rows.tracks(), tuple(stats), output)


@dataclass(frozen=True)
class ScenarioRun:
    """Simulate → track → evaluate, all of one run."""

    simulation: Simulation
    run: TrackingRun
    evaluation: Evaluation
    #: The line naming the new-target density chosen (None when the user set it).
    birth_note: str | None = None
    #: The bias estimation (``TrackOptions.estimate_bias``;
    #: :class:`~mhtrack.pipeline.registration.Registration`), else None.
    registration: Any = None

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


def scenario_source(scenario: Scenario, plots: PlotTable) -> MemorySource:
    """A simulation's plots as a source: with its scenario, and — plots with their own
    times — its radars (coverage, per-radar clutter, the lat/lon of the outputs)."""
    sensors = scenario.sensor_set() if plots.timed else None
    return MemorySource(plots, name=scenario.name, sensors=sensors, scenario=scenario)


def run_scenario(
    scenario: Scenario,
    seed: int,
    tracker: str = "mht",
    config: MHTConfig | None = None,
    *,
    clutter_density: float | None = None,
    cutoff: float | None = None,
    order: float | None = None,
    progress: bool = False,
    birth: str | None = None,
    theta_deg: float | None = None,
    fusion: str | None = None,
    output: str = "history",
    clutter_params: dict[str, Any] | None = None,
    options: TrackOptions | None = None,
    attributes: AttributeOptions | None = None,
) -> ScenarioRun:
    """Simulate ``scenario`` with ``seed``, run the tracker on it and evaluate.

    The tracker is ``options`` (:class:`~mhtrack.pipeline.TrackOptions`) when given, else
    the one the keywords name (``tracker``, ``clutter_density``, ``birth``,
    ``theta_deg``, ``fusion``, ``output``, ``clutter_params``); ``config``: the base
    configuration (default :func:`~mhtrack.build.default_config` of the scenario). The
    run goes through :class:`~mhtrack.pipeline.Pipeline` as ``mhtrack track`` does: a
    scenario of rotating radars (plots with their own times) is tracked frame by frame,
    unfused, with the radars' coverage and per-radar clutter; scans of several sensors
    are fused by default. ``cutoff``/``order``: OSPA/GOSPA's (default
    :func:`~mhtrack.metrics.evaluate`'s). ``attributes``: the plots' secondary-radar
    attributes (:func:`~mhtrack.scenario.identity.with_attributes`; ``None``: none, as
    :func:`~mhtrack.scenario.simulate` draws)."""
    from mhtrack.metrics import evaluate
    from mhtrack.scenario import simulate

    if options is None:
        options = TrackOptions(tracker=tracker, clutter_density=clutter_density, birth=birth,
                               birth_theta_deg=theta_deg, fusion=fusion, output=output,
                               clutter_params=clutter_params)
    sim = simulate(scenario, seed=seed)
    if attributes is not None:
        from mhtrack.scenario.identity import with_attributes

        sim = with_attributes(sim, attributes)
    pipe = Pipeline(scenario_source(scenario, sim.plots), options, config=config)
    rows = TrackCollector(pipe.output)
    result = pipe.run([rows], progress=progress)
    run = TrackingRun(options.tracker, rows.tracks(), result.stats, pipe.output)
    metric = {k: v for k, v in (("cutoff", cutoff), ("order", order)) if v is not None}
    ev = evaluate(run.tracks, sim.truth, plots=sim.plots, **metric)
    return ScenarioRun(sim, run, ev, pipe.birth_note, pipe.registration)
