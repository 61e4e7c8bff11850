"""Simulate a :class:`~mhtrack.scenario.spec.Scenario`: truth, target plots and clutter.

For every scan ``k`` (time ``t = k·T``) and every sensor, in increasing sensor id:

1. each live target is detected with the sensor's ``P_D`` (independent Bernoulli draws);
   a detected target gives one plot from ``sensor.observe`` (Cartesian noise, or noisy
   range/bearing converted by the unbiased converted measurement);
2. the sensor draws its own clutter, ``clutter.sample(rng, k)`` — a Poisson count with
   mean ``λ_k`` spread by the model's density (P1 §1.2) — placed with ``sensor.place``
   (for a polar radar: the range/bearing pointing at the clutter point);
3. the sensor's target and clutter plots are shuffled together, so the order of the plots
   within a scan and sensor leaks nothing about their origin.

Random streams. Every random draw comes from a generator ``np.random.default_rng`` seeded
with a ``SeedSequence(seed, spawn_key=…)`` whose key is built from integers only:
``(0, target id)`` for a target's truth noise and ``(1, sensor id, scan)`` for the plots
of one sensor at one scan. The output therefore depends on nothing but the seed and the
scenario — not on dict order or Python's hash seed — and adding a sensor or a target
leaves the draws of the others unchanged.

Rotating radars (:class:`~mhtrack.models.sensors.RotatingRadar`, a scenario whose sensors
have a ``period``) are simulated by :mod:`mhtrack.scenario.sweep` instead: plots timed by
the beam, on the WGS-84 ellipsoid, the truth sampled every ``truth_dt`` seconds along
:mod:`mhtrack.scenario.trajectory`'s continuous trajectories.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from mhtrack.models.clutter import TimeVaryingClutter
from mhtrack.models.sensors import PolarRadar
from mhtrack.records import CLUTTER, PlotTable, TruthTable
from mhtrack.scenario.spec import Scenario
from mhtrack.scenario.targets import Target
from mhtrack.scenario.trajectory import sample_truth, segments

log = logging.getLogger("mhtrack.scenario")

_TRUTH_STREAM = 0
_PLOT_STREAM = 1


@dataclass(frozen=True, eq=False)
class Simulation:
    """Result of :func:`simulate`: the plots (sorted by scan, then sensor id; ``origin`` =
    target id or −1), the truth (sorted by scan, then target id), and what made them.
    With rotating radars the plots are timed (``plots.timed``, ``scan`` = frame) and the
    truth's ``scan`` is the sample index."""

    scenario: Scenario
    seed: int
    plots: PlotTable
    truth: TruthTable


def _rng(seed: int, *key: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=key))


def simulate_truth(scenario: Scenario, seed: int = 0) -> TruthTable:
    """True states of every target at every scan it is alive in ``scenario.scans``.

    :class:`Target` s move as in :meth:`Target.states` (process noise ``truth_sigma_v``
    from the stream ``(0, target id)``); :class:`RecordedTarget` s give their rows.
    """
    first, last, T = scenario.first, scenario.last, scenario.T
    scans, ids, states = [], [], []
    for t in scenario.targets:
        if isinstance(t, Target):
            rng = _rng(seed, _TRUTH_STREAM, t.id) if scenario.truth_sigma_v > 0 else None
            k, x = t.states(first, last, T, scenario.truth_sigma_v, rng)
        else:
            k, x = t.states_in(first, last)
        scans.append(k)
        ids.append(np.full(len(k), t.id, np.int64))
        states.append(x)
    if scans:
        scan = np.concatenate(scans)
        tid = np.concatenate(ids)
        x = np.concatenate(states).reshape(-1, 4)
    else:
        scan, tid, x = np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 4))
    order = np.lexsort((tid, scan))
    scan, tid, x = scan[order], tid[order], x[order]
    return TruthTable(
        scan=scan,
        time=scan * T,
        target_id=tid,
        x=np.ascontiguousarray(x[:, 0]),
        y=np.ascontiguousarray(x[:, 2]),
        vx=np.ascontiguousarray(x[:, 1]),
        vy=np.ascontiguousarray(x[:, 3]),
    )


def simulate(scenario: Scenario, seed: int = 0) -> Simulation:
    """Simulate ``scenario`` with random ``seed`` (an integer ``>= 0``).

    The same seed always gives identical arrays. ``plots`` has a ``scan_times`` entry for
    every scan (empty scans included); ``range``/``bearing`` (m, degrees clockwise from
    north; NaN on Cartesian rows) when any sensor is polar; per-plot ``R`` unless all
    sensors are Cartesian with one σ (then the tracker's own ``R = σ² I`` applies).
    Rotating radars: :func:`simulate_rotating`.
    """
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise ValueError(f"seed: expected an integer >= 0, got {seed!r}")
    seed = int(seed)
    if scenario.rotating:
        return simulate_rotating(scenario, seed)
    truth = simulate_truth(scenario, seed)
    sensors = sorted(zip(scenario.sensors, scenario.pd, strict=True), key=lambda s: s[0].id)
    any_polar = any(isinstance(s, PolarRadar) for s, _ in sensors)
    keep_R = any_polar or len({s.sigma for s, _ in sensors}) > 1  # type: ignore[union-attr]

    bounds = np.searchsorted(truth.scan, scenario.scan_indices(), side="left")
    ends = np.searchsorted(truth.scan, scenario.scan_indices(), side="right")
    pos = truth.positions
    parts: dict[str, list[np.ndarray]] = {
        k: [] for k in ("scan", "sensor", "z", "R", "rb", "origin")
    }
    debug = log.isEnabledFor(logging.DEBUG)  # checked once: the per-scan line costs nothing
    for k, a, b in zip(
        scenario.scan_indices().tolist(), bounds.tolist(), ends.tolist(), strict=True
    ):
        model = scenario.clutter
        if isinstance(model, TimeVaryingClutter):
            model = model.at(k)  # interpolate once per scan, not once per sensor
        live_ids, live_pos = truth.target_id[a:b], pos[a:b]
        for sensor, pd in sensors:
            rng = _rng(seed, _PLOT_STREAM, sensor.id, k)
            hit = rng.random(len(live_ids)) < pd
            det = sensor.observe(rng, live_pos[hit])
            clut = sensor.place(model.sample(rng, k))
            n = len(det.z) + len(clut.z)
            perm = rng.permutation(n)
            parts["z"].append(np.concatenate((det.z, clut.z))[perm])
            parts["R"].append(np.concatenate((det.R, clut.R))[perm])
            parts["origin"].append(
                np.concatenate((live_ids[hit], np.full(len(clut.z), CLUTTER, np.int64)))[perm]
            )
            if isinstance(sensor, PolarRadar):
                parts["rb"].append(np.concatenate((det.range_bearing, clut.range_bearing))[perm])
            elif any_polar:
                parts["rb"].append(np.full((n, 2), np.nan))
            parts["scan"].append(np.full(n, k, np.int64))
            parts["sensor"].append(np.full(n, sensor.id, np.int64))
            if debug:
                log.debug("simulate: scan %d, sensor %d: %d targets, %d detected, %d clutter",
                          k, sensor.id, len(live_ids), len(det.z), len(clut.z))

    scan = np.concatenate(parts["scan"])
    z = np.concatenate(parts["z"]).reshape(-1, 2)
    rb = np.concatenate(parts["rb"]).reshape(-1, 2) if any_polar else None
    plots = PlotTable(
        scan=scan,
        time=scan * scenario.T,
        sensor=np.concatenate(parts["sensor"]),
        x=np.ascontiguousarray(z[:, 0]),
        y=np.ascontiguousarray(z[:, 1]),
        range=None if rb is None else np.ascontiguousarray(rb[:, 0]),
        bearing=None if rb is None else np.ascontiguousarray(rb[:, 1]),
        origin=np.concatenate(parts["origin"]),
        R=np.concatenate(parts["R"]).reshape(-1, 2, 2) if keep_R else None,
        scan_times=(scenario.scan_indices(), scenario.scan_times()),
    )
    log.info("simulate %s (seed %d): %d scans, %d plots, %d targets", scenario.name, seed,
             len(scenario.scan_indices()), len(plots), len(np.unique(truth.target_id)))
    return Simulation(scenario=scenario, seed=seed, plots=plots, truth=truth)


def simulate_rotating(scenario: Scenario, seed: int = 0) -> Simulation:
    """Simulate a scenario of rotating radars over ``[first·T, last·T]`` seconds.

    ``plots``: a timed :class:`PlotTable` (``time`` = when the beam crossed the plot;
    ``scan`` = frame of :func:`~mhtrack.frames.make_frames`; ``range``, ``bearing`` as
    measured; ``x, y, R`` in the scenario's local frame; ``origin``), see
    :mod:`mhtrack.scenario.sweep`. ``truth``: every ``truth_dt`` seconds from the start
    (``scan`` = sample index), the targets alive then, on their Hermite trajectories
    (:mod:`mhtrack.scenario.trajectory`) in the local frame.
    """
    from mhtrack.scenario.sweep import rotating_plots  # pyproj: imported only when used

    grid = simulate_truth(scenario, seed)
    segs = segments(grid)
    sensor_set = scenario.sensor_set()
    frame = sensor_set.frame()
    sites = {s.id: sensor_set.site_latlon(s.id) for s in scenario.sensors}
    window = (float(scenario.first * scenario.T), float(scenario.last * scenario.T))
    radars = sorted(zip(scenario.sensors, scenario.pd, strict=True), key=lambda s: s[0].id)
    plots = rotating_plots(radars, frame, sites, segs, window, seed,  # type: ignore[arg-type]
                           scenario.clutter_scene)
    truth = sample_truth(segs, *window, scenario.truth_dt)
    return Simulation(scenario=scenario, seed=seed, plots=plots, truth=truth)
