"""Simulate rotating radars (:class:`~mhtrack.models.sensors.RotatingRadar`): each plot is
timed when the beam crosses it.

**Geometry.** Sites and targets are on the WGS-84 ellipsoid: a target at local ``(x, y)``
(the scenario's :class:`~mhtrack.models.geodesy.LocalFrame`) has the exact geodesic range
and azimuth ``(r, b)`` from the site (:func:`~mhtrack.models.geodesy.local_to_polar`).

**Crossing times.** The beam points at ``β(t) = φ + ω t`` (``ω = 360/P`` degrees per
second, unwrapped); a target whose (unwrapped) bearing is ``b̃(t)`` is crossed when the
lag ``D(t) = φ + ω t − b̃(t)`` is a multiple of 360°: crossing ``m`` solves
``D(t) = 360 m``. ``D`` is tabulated on the target's truth grid (bearings unwrapped
along it); each grid interval holds the ``m`` with ``D(t_g) <= 360 m < D(t_{g+1})``,
started at the linear interpolation of ``D`` and refined by the fixed point::

    t ← (360 m + b̃(t) − φ) / ω          (b̃: the bearing at t, unwrapped next to the grid's)

It contracts by ``q = |db/dt| / ω`` per step (the target's angular rate seen from the
site over the beam's): an airliner at 250 m/s and 20 km from a 12 s radar has
``q = 0.72°/s / 30°/s = 0.024``, so each step gains more than a factor 40. The iteration
stops when a step moves no crossing by more than :data:`TIME_TOL` (1 µs: the remaining
error is below ``q/(1 − q)`` of that, and the beam turns by ``ω·TIME_TOL`` = 9·10⁻⁵°
in 1 µs at P = 4 s) or after :data:`MAX_ITER` steps; measured on ``opensky-radars``:
3–4 steps. Only a target within ``v P / 2π`` of the site (under 500 m
for these speeds and periods) can have ``q >= 1``; the crossing is then the last iterate.

**Detections.** Each crossing within ``max_range`` is detected with the radar's ``P_D``
and reported with range and bearing plus Gaussian noise ``σr``, ``σθ`` (range folded to
``|r|``, bearing wrapped to ``[0, 360)``), after the radar's registration bias, if it has
one (``r_m = g r + Δr``, ``θ_m = θ + Δθ``: ``RotatingRadar.range_gain``, ``range_bias``,
``azimuth_bias_deg``; clutter is drawn in the measured space). **Clutter** per rotation
(the beam's turn from north to north): :func:`~mhtrack.models.clutter.sample_range_azimuth`,
each plot timed when the beam points at its bearing. Every plot is converted to the local
frame with its covariance by :func:`~mhtrack.models.geodesy.polar_to_local`.

**Random streams** (integer spawn keys, as in :mod:`mhtrack.scenario.simulate`):
``(2, sensor id, target id)`` for a target's detections and noise by one radar,
``(3, sensor id, rotation)`` for one rotation's clutter (rotation 0: the one under way at
the start), ``(4, sensor id, rotation)`` for its :class:`~mhtrack.models.clutter_scene.
ClutterScene` clutter.

**Clutter scene** (a scenario's ``clutter_scene``): each rotation ``n`` of a radar also
draws the scene's clutter as it stands at the rotation's middle ``τ_n = t₀ + P/2``
(``t₀``: the beam at north), in the local plane about the radar's site
(:meth:`ClutterScene.sample`); each point gets its exact range and bearing
(:func:`~mhtrack.models.geodesy.local_to_polar`), is dropped beyond ``max_range`` and is
timed when the beam points at it. The true intensity of that rotation is
:func:`mhtrack.scenario.scene_truth.radar_intensity` at ``τ_n``.
"""

from __future__ import annotations

import numpy as np

from mhtrack.frames import frame_lengths, make_frames
from mhtrack.models.clutter import sample_range_azimuth
from mhtrack.models.clutter_scene import ClutterScene
from mhtrack.models.geodesy import LocalFrame, local_to_polar, polar_to_local
from mhtrack.models.sensors import RotatingRadar
from mhtrack.records import CLUTTER, PlotTable
from mhtrack.scenario.trajectory import Segment

#: Convergence tolerance of the crossing-time iteration (s): 10 ns.
TIME_TOL = 1e-8
#: Most fixed-point steps per crossing.
MAX_ITER = 30

_DETECTION_STREAM = 2
_CLUTTER_STREAM = 3
_SCENE_STREAM = 4


def _rng(seed: int, *key: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=key))


def _biased(radar: RotatingRadar) -> bool:
    """The radar has a registration bias (``RotatingRadar.range_bias`` …)."""
    return (radar.range_bias, radar.range_gain, radar.azimuth_bias_deg) != (0.0, 1.0, 0.0)


def _wrap180(a: np.ndarray) -> np.ndarray:
    return (a + 180.0) % 360.0 - 180.0


def crossings(
    radar: RotatingRadar, frame: LocalFrame, site: tuple[float, float], seg: Segment
) -> np.ndarray:
    """Times (s, increasing) when the beam of ``radar`` at ``site`` (lat, lon) crosses the
    target of ``seg`` during the segment (module docstring)."""
    if len(seg.t) < 2:
        return np.zeros(0)
    w, phi = radar.rate_deg, radar.phase
    _, b = local_to_polar(frame, *site, seg.p[:, 0], seg.p[:, 1])
    bu = np.unwrap(b, period=360.0)
    D = phi + w * seg.t - bu
    lo = np.ceil(D[:-1] / 360.0).astype(np.int64)
    hi = np.ceil(D[1:] / 360.0).astype(np.int64) - 1
    count = np.maximum(hi - lo + 1, 0)
    g = np.repeat(np.arange(len(seg.t) - 1), count)
    if g.size == 0:
        return np.zeros(0)
    m = lo[g] + (np.arange(g.size) - np.repeat(np.cumsum(count) - count, count))
    t = seg.t[g] + (360.0 * m - D[g]) / (D[g + 1] - D[g]) * (seg.t[g + 1] - seg.t[g])
    for _ in range(MAX_ITER):
        p, _v = seg.state(t)
        _, bt = local_to_polar(frame, *site, p[:, 0], p[:, 1])
        ref = np.interp(t, seg.t, bu)
        new = np.clip((360.0 * m + ref + _wrap180(bt - ref) - phi) / w, seg.start, seg.end)
        step = np.max(np.abs(new - t))
        t = new
        if step <= TIME_TOL:
            break
    return np.sort(t)


def _rotation_starts(radar: RotatingRadar, start: float, end: float) -> np.ndarray:
    """Times the beam points north, from the last one at or before ``start`` to ``end``."""
    k0 = np.floor((radar.phase + radar.rate_deg * start) / 360.0)
    t0 = (360.0 * k0 - radar.phase) / radar.rate_deg
    n = int(np.floor((end - t0) / radar.period)) + 1
    return t0 + radar.period * np.arange(n)


#: Earth radius (m) for the reach pre-filter's scale bound: the WGS-84 semi-minor axis (the
#: smaller radius gives the larger bound).
_EARTH_R = 6_356_752.0
#: Largest distance from the frame's origin (rad of arc) up to which the pre-filter acts.
_FILTER_MAX_ARC = 1.0


def may_reach(radar: RotatingRadar, site_xy: np.ndarray, seg: Segment) -> bool:
    """False only when the target of ``seg`` is out of ``radar``'s ``max_range`` all
    along: a bound in the local (azimuthal-equidistant) frame, where the planar distance
    of two points is at most ``k`` times their geodesic distance, ``k = a/sin a`` the
    frame's largest scale at ``a`` (the arc from the origin, ≤ 1 rad) of the farther
    point; with 1 % and 10 km to spare, plus the longest distance the target flies
    between two truth samples (it is only checked at them).
    Skipping such a target leaves every other plot unchanged (each target has its own
    random stream)."""
    if radar.max_range is None or len(seg.t) == 0:
        return True
    arc = (max(float(np.hypot(*site_xy)), float(np.hypot(seg.p[:, 0], seg.p[:, 1]).max()))
           + radar.max_range) / _EARTH_R
    if arc >= _FILTER_MAX_ARC:
        return True
    k = arc / np.sin(arc) if arc > 0 else 1.0
    d = np.hypot(seg.p[:, 0] - site_xy[0], seg.p[:, 1] - site_xy[1]).min()
    hop = 0.0
    if len(seg.t) > 1:
        hop = float(np.hypot(seg.v[:, 0], seg.v[:, 1]).max() * np.diff(seg.t).max())
    return bool(d <= 1.01 * k * radar.max_range + 10_000.0 + hop)


def radar_plots(
    radar: RotatingRadar,
    pd: float,
    frame: LocalFrame,
    site: tuple[float, float],
    segs: list[Segment],
    window: tuple[float, float],
    seed: int,
    scene: ClutterScene | None = None,
) -> dict[str, np.ndarray]:
    """One radar's plots over ``window`` (s, inclusive): columns ``time, range, bearing,
    origin`` (unsorted: targets in ``segs`` order, then clutter by rotation, then the
    ``scene``'s clutter by rotation about the site's position in ``frame``)."""
    cols: dict[str, list[np.ndarray]] = {k: [] for k in ("time", "range", "bearing", "origin")}
    site_xy = np.array(frame.to_local(*site), float).ravel()
    for seg in segs:
        if not may_reach(radar, site_xy, seg):
            continue
        t = crossings(radar, frame, site, seg)
        if t.size == 0:
            continue
        rng = _rng(seed, _DETECTION_STREAM, radar.id, seg.target_id)
        p, _ = seg.state(t)
        r, b = local_to_polar(frame, *site, p[:, 0], p[:, 1])
        hit = rng.random(t.size) < pd
        nr = rng.normal(scale=radar.sigma_range, size=t.size)
        nb = rng.normal(scale=radar.sigma_bearing_deg, size=t.size)
        keep = hit & (window[0] <= t) & (t <= window[1])
        if radar.max_range is not None:
            keep &= r <= radar.max_range
        cols["time"].append(t[keep])
        if _biased(radar):  # registration bias (none: the former floats exactly)
            r, b = radar.range_gain * r + radar.range_bias, b + radar.azimuth_bias_deg
        cols["range"].append(np.abs(r + nr)[keep])
        cols["bearing"].append(((b + nb) % 360.0)[keep])
        cols["origin"].append(np.full(int(keep.sum()), seg.target_id, np.int64))
    for n, t0 in enumerate(_rotation_starts(radar, *window).tolist()):
        rng = _rng(seed, _CLUTTER_STREAM, radar.id, n)
        r, b = sample_range_azimuth(rng, radar.clutter_rate, radar.max_range,
                                    radar.clutter_patches)
        t = t0 + b / radar.rate_deg
        keep = (window[0] <= t) & (t <= window[1])
        cols["time"].append(t[keep])
        cols["range"].append(r[keep])
        cols["bearing"].append(b[keep])
        cols["origin"].append(np.full(int(keep.sum()), CLUTTER, np.int64))
    if scene is not None:
        for k, v in _scene_plots(radar, frame, site, site_xy, scene, window, seed).items():
            cols[k].append(v)
    return {k: np.concatenate(v) if v else np.zeros(0) for k, v in cols.items()}


def rotation_middle(radar: RotatingRadar, t: np.ndarray | float) -> np.ndarray:
    """``τ``: the middle of the rotation (north to north) under way at time(s) ``t``."""
    k = np.floor((radar.phase + radar.rate_deg * np.asarray(t, float)) / 360.0)
    return (360.0 * k - radar.phase) / radar.rate_deg + 0.5 * radar.period


def _scene_plots(radar: RotatingRadar, frame: LocalFrame, site: tuple[float, float],
                 site_xy: np.ndarray, scene: ClutterScene,
                 window: tuple[float, float], seed: int) -> dict[str, np.ndarray]:
    """The scene's clutter of one radar, rotation by rotation (module docstring), about
    the site's local position ``site_xy``."""
    cols: dict[str, list[np.ndarray]] = {k: [] for k in ("time", "range", "bearing", "origin")}
    for n, t0 in enumerate(_rotation_starts(radar, *window).tolist()):
        rng = _rng(seed, _SCENE_STREAM, radar.id, n)
        xy = scene.sample(rng, radar.id, t0 + 0.5 * radar.period, site_xy)
        r, b = local_to_polar(frame, *site, xy[:, 0], xy[:, 1])
        t = t0 + b / radar.rate_deg
        keep = (window[0] <= t) & (t <= window[1])
        if radar.max_range is not None:
            keep &= r <= radar.max_range
        cols["time"].append(t[keep])
        cols["range"].append(r[keep])
        cols["bearing"].append(b[keep])
        cols["origin"].append(np.full(int(keep.sum()), CLUTTER, np.int64))
    return {k: np.concatenate(v) for k, v in cols.items()}


def rotating_plots(
    radars: list[tuple[RotatingRadar, float]],
    frame: LocalFrame,
    sites: dict[int, tuple[float, float]],
    segs: list[Segment],
    window: tuple[float, float],
    seed: int,
    scene: ClutterScene | None = None,
) -> PlotTable:
    """The timed :class:`~mhtrack.records.PlotTable` of several rotating radars
    ``(radar, P_D)`` at ``sites`` (id → lat, lon): rows cut into frames by
    :func:`~mhtrack.frames.make_frames` (one radar, at most an eighth of its rotation)
    and sorted by frame, then time; ``scene``: a clutter scene drawn about each site on top
    of each radar's own clutter; ``x, y, R`` from
    :func:`~mhtrack.models.geodesy.polar_to_local`; ``origin`` target id or −1."""
    parts = []
    for radar, pd in radars:
        c = radar_plots(radar, pd, frame, sites[radar.id], segs, window, seed, scene)
        z, R = polar_to_local(frame, *sites[radar.id], c["range"], c["bearing"],
                              radar.sigma_range, radar.sigma_bearing_deg)
        c.update(sensor=np.full(len(c["time"]), radar.id, np.int64), z=z.reshape(-1, 2),
                 R=R.reshape(-1, 2, 2))
        parts.append(c)
    col = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    frame_idx, order = make_frames(col["time"], col["sensor"],
                                   frame_lengths({r.id: r.period for r, _ in radars}))
    z = col["z"][order]
    return PlotTable(
        scan=frame_idx[order],
        time=col["time"][order],
        sensor=col["sensor"][order],
        x=np.ascontiguousarray(z[:, 0]),
        y=np.ascontiguousarray(z[:, 1]),
        range=col["range"][order],
        bearing=col["bearing"][order],
        origin=col["origin"][order].astype(np.int64),
        R=col["R"][order],
        timed=True,
    )
