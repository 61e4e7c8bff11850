"""Sensor coverage: which hypotheses the frame's sensor looked at, and with what ``P_D``.

A leaf is scored as missed only by a sensor that could have seen it (Blackman & Popoli
1999 §16.2; MATLAB ``trackerTOMHT``'s detectable tracks): the radar's beam swept the
leaf's predicted position during the frame, and the position is within the radar's
instrumented range. A :class:`Coverage` gives, per leaf, the detection probability
``P_D`` of the frame's sensor (0: not looked at) and ``P_D`` of the frame's plots:

* :class:`Everywhere` — every leaf, every scan, one ``P_D`` (P1's synchronous scans; the
  default, bit for bit today's tracker);
* :class:`RadarCoverage` — rotating radars of a :class:`~mhtrack.models.radars.SensorSet`.

The miss increment becomes ``ln(1 − P_D·P_G)`` with the leaf's own ``P_D``
(:func:`mhtrack.mht.scoring.miss_increments`); a tree none of whose leaves was looked at
is carried unchanged (no child, no score change; :mod:`mhtrack.mht.tracker`).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from mhtrack.kernels import mean
from mhtrack.mht.reach import ReachEstimator
from mhtrack.models.radars import SensorSet
from mhtrack.records import Scan

#: Largest ``P_D`` a coverage assumes (as ``mhtrack.build.MAX_TRACKER_PD``): at ``P_D = 1``
#: a single lost plot would cost ``ln 0``.
MAX_COVERAGE_PD = 0.999
#: Widest band (degrees) on each edge of a swept sector where a look is uncertain.
MAX_EDGE_DEG = 10.0


@dataclass(frozen=True, slots=True)
class Looks:
    """What a frame's sensor saw of each leaf: ``pd`` (L,) its ``P_D`` (0: not looked
    at; gating and the update use it) and ``certain`` (L,) whether the look is sure enough
    to score a miss — a leaf on the edge of the swept sector may be seen by this frame or
    by the sensor's next one, so its miss costs nothing (``ln(1 − 0)``) while a plot may
    still update it. ``uniform``: not ``None`` when every leaf was looked at, with
    certainty and this one ``P_D`` (``pd`` all that value, ``certain`` all true; P1's
    scans, :class:`Everywhere`), so the stages may skip their per-leaf tests."""

    pd: np.ndarray
    certain: np.ndarray
    uniform: float | None = None

    @property
    def miss_pd(self) -> np.ndarray:
        """``P_D`` of the miss increment: ``pd`` where certain, else 0."""
        return np.where(self.certain, self.pd, 0.0)


class Coverage(ABC):
    """Detection probability of the frame's sensor for each predicted leaf.

    Required: :meth:`detection` and :meth:`plot_pd`. Optional hooks: :meth:`arrays` /
    :meth:`set_arrays` for a coverage that keeps state across frames (saved with the
    tracker; default: none); :attr:`per_tree_looks` (default ``False``).
    """

    #: Whether a frame may leave trees unstepped (``False``: every tree steps every scan,
    #: P1). Then a tree's window columns are its own looks, and two trees may hold one
    #: plot in different columns: the global hypothesis, the clustering and the hand-over
    #: identify a plot by its id alone (``by_id`` of
    #: :func:`~mhtrack.mht.hypothesis.best_hypothesis`; ids unique over the window, as a
    #: :class:`~mhtrack.records.PlotTable`'s rows are).
    per_tree_looks: bool = False
    #: The rotating sensors whose sector frames the tracker's store holds (``max_trees``'
    #: floor is per such sensor, :func:`mhtrack.mht.caps.scaled_limits`); 1: one scan
    #: holds the scene (also a fused scan, or sensors without a rotation period).
    n_sensors: int = 1

    @abstractmethod
    def detection(self, scan: Scan, x: np.ndarray, P: np.ndarray,
                  time: np.ndarray) -> Looks:
        """:class:`Looks` of ``scan``'s sensor at leaves with states ``x`` (L, 4), ``P``
        (L, 4, 4) at their own times ``time`` (L,). Called once per frame."""

    @abstractmethod
    def plot_pd(self, scan: Scan) -> float:
        """``P_D`` of the sensor that made ``scan``'s plots (the update increment and the
        birth score, P1 eqs. 5 / 15)."""

    def plot_pds(self, scan: Scan) -> float | np.ndarray:
        """``P_D`` of each of ``scan``'s plots in the update increment: a float when every
        plot has the same (default: :meth:`plot_pd`), else one per plot (a radar whose
        plot types have their own ``P_D``, :class:`RadarCoverage`)."""
        return self.plot_pd(scan)

    def arrays(self) -> dict[str, np.ndarray]:
        """State to save with the tracker (``coverage__*`` arrays). Default: none."""
        return {}

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:  # noqa: B027 (optional hook)
        """Restore what :meth:`arrays` returned. Default: nothing."""


class Everywhere(Coverage):
    """Every leaf is looked at with the same ``p_detection`` (P1's scans)."""

    def __init__(self, p_detection: float) -> None:
        if not 0.0 < p_detection < 1.0:
            raise ValueError(f"p_detection must be in (0, 1), got {p_detection}")
        self.p_detection = float(p_detection)

    def detection(self, scan: Scan, x: np.ndarray, P: np.ndarray,
                  time: np.ndarray) -> Looks:
        return Looks(np.full(len(x), self.p_detection), np.ones(len(x), bool),
                     self.p_detection)

    def plot_pd(self, scan: Scan) -> float:
        return self.p_detection


def grid_bearing(dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """Bearing (degrees clockwise from the local frame's north, in [0, 360)) of ``(dx, dy)``."""
    return np.degrees(np.arctan2(dx, dy)) % 360.0


class RadarCoverage(Coverage):
    """Coverage of the radars of ``sensors``; one frame holds one sensor's plots.

    For the frame's sensor (site ``s``, ``P_D`` capped at ``max_pd``, ``max_range``,
    rotation ``period`` ``T_r``, clockwise) a leaf at position ``p(t) = p + v (t − t_leaf)``
    is looked at when ``|p(t_f) − s| ≤ max_range`` and, for a rotating radar, the beam
    crossed it during ``(t₀, t_f]``: ``t_f`` the frame's time (its latest plot), ``t₀`` the
    end of the sensor's previous frame (the first frame: its first plot). The frames of
    a sensor thus tile its time line, and a target is looked at once per rotation. The
    beam's azimuth is ``a(t) = a_f − ω (t_f − t)``, ``ω = 360°/T_r``, with ``a_f`` the
    circular mean of the frame's plots' bearings carried to ``t_f``, ``β_i + ω (t_f − t_i)``
    (each plot was timed when the beam crossed it). The beam–leaf angle ``φ(t) = (a(t) −
    θ(t)) mod 360`` grows with ``t`` (a target's bearing rate is far below ``ω``), so the
    beam crossed the leaf iff ``φ(t_f) < φ(t₀)`` or ``ω (t_f − t₀) ≥ 360°``. Bearings are
    the local frame's grid bearings of positions from the site (the plots' and the
    leaves' alike; they differ from geodesic azimuths by the meridian convergence, which
    cancels between the two). A sensor without a period (or without a site) looks at
    everything within range every frame.

    *Reach.* A radar without ``max_range`` (real sensors files rarely give one) has its
    reach learned from its own plots (:mod:`mhtrack.mht.reach`): a leaf beyond it is looked
    at but not certainly — a plot may update it, no miss is charged.

    *Sector edges.* A leaf whose bearing is within ``band`` of either edge of the swept
    sector — ``3σ`` of its own bearing (``√max(Pxx, Pyy)/r``) plus ``3σθ`` of the radar,
    at most :data:`MAX_EDGE_DEG` — may be seen by this frame or by the sensor's next one:
    it is looked at (gated, ``P_D`` for an update) by both, but a miss is scored only
    where the look is certain (:class:`Looks`). Measured on the tests' two radars: with
    sharp edges 24 of 202 target plots fell on a leaf the coverage had given to the
    neighbouring frame (a duplicate track each time); with the band, none.
    """

    per_tree_looks = True

    def __init__(self, sensors: SensorSet, *, max_pd: float = MAX_COVERAGE_PD,
                 learn_reach: bool = True) -> None:
        self.sensors = sensors
        # sector frames only: a sensor without a period looks at everything each frame
        self.n_sensors = max(sum(s.period is not None for s in sensors.sensors), 1)
        self.max_pd = float(max_pd)
        #: Whether a radar without ``max_range`` has its reach learned (else it sees to
        #: infinity, the former rule; kept for comparisons).
        self.learn_reach = bool(learn_reach)
        self._last_end: dict[int, float] = {}
        self._site: dict[int, tuple[float, float] | None] = {}
        #: The reach of each radar without ``max_range``, learned from its own plots
        #: (:mod:`mhtrack.mht.reach`).
        self.reach = ReachEstimator({s.id: s.period for s in sensors.sensors
                                     if s.period is not None and s.max_range is None})

    def _sensor_id(self, scan: Scan) -> int:
        sensor = np.asarray(scan.sensor, np.int64)
        if sensor.size and (sensor == sensor.flat[0]).all():
            return int(sensor.flat[0])
        ids = np.unique(sensor)
        if ids.size != 1:
            raise ValueError(f"frame {scan.index}: RadarCoverage needs the plots of one "
                             f"sensor per frame, got sensors {ids.tolist()}")
        return int(ids[0])

    def _site_of(self, sid: int) -> tuple[float, float] | None:
        if sid not in self._site:
            self._site[sid] = (self.sensors.site_xy(sid)
                               if self.sensors.sensor(sid).has_site else None)
        return self._site[sid]

    def plot_pd(self, scan: Scan) -> float:
        return min(self.sensors.sensor(self._sensor_id(scan)).pd, self.max_pd)

    def plot_pds(self, scan: Scan) -> float | np.ndarray:
        """Per plot the ``P_D`` of its type where the sensors file gives one
        (:meth:`~mhtrack.models.radars.RadarSensor.pds`, capped at ``max_pd`` as the
        sensor's), else :meth:`plot_pd`'s float: without type tables, or plots without
        types, exactly today's."""
        sensor = self.sensors.sensor(self._sensor_id(scan))
        types = None if scan.attrs is None else scan.attrs.plot_type
        pds = sensor.pds(types)
        if isinstance(pds, float):
            return min(pds, self.max_pd)
        return np.minimum(pds, self.max_pd)

    def detection(self, scan: Scan, x: np.ndarray, P: np.ndarray,
                  time: np.ndarray) -> Looks:
        sid = self._sensor_id(scan)
        sensor = self.sensors.sensor(sid)
        pd = min(sensor.pd, self.max_pd)
        tf = float(scan.time)
        t_plots = scan.plot_times()
        t0 = self._last_end.get(sid, float(t_plots.min()) if len(scan) else tf)
        self._last_end[sid] = tf
        site = self._site_of(sid)
        x = np.asarray(x, float).reshape(-1, 4)
        looked = np.ones(len(x), bool)
        if site is None:
            return Looks(np.full(len(x), pd), looked)
        dt = tf - np.asarray(time, float)
        px = x[:, 0] + x[:, 1] * dt - site[0]
        py = x[:, 2] + x[:, 3] * dt - site[1]
        dist = np.hypot(px, py)
        if sensor.max_range is not None:
            looked &= dist <= sensor.max_range
            inside = looked
        elif self.learn_reach:  # no miss charged beyond the reach learned from its plots
            inside = self._learned_reach(sid, scan, site, px, py, dist)
        else:
            inside = looked
        if sensor.period is None or not len(scan):
            return Looks(np.where(looked, pd, 0.0), looked & inside)
        omega = 360.0 / sensor.period
        span = tf - t0
        if omega * span >= 360.0:
            return Looks(np.where(looked, pd, 0.0), looked & inside)
        # the beam's test only where the range test passed (elementwise: the same values
        # as over every leaf; the others are not looked at)
        r = None if looked.all() else looked.nonzero()[0]
        if r is not None:
            x, P, px, py, dist = x.take(r, axis=0), P.take(r, axis=0), px.take(r), \
                py.take(r), dist.take(r)
        z = np.asarray(scan.z, float).reshape(-1, 2)
        beam = np.radians(grid_bearing(z[:, 0] - site[0], z[:, 1] - site[1])
                          + omega * (tf - t_plots))
        # the circular mean
        a_f = math.degrees(math.atan2(mean(np.sin(beam)), mean(np.cos(beam))))
        d0 = t0 - tf
        q0 = grid_bearing(px + x[:, 1] * d0, py + x[:, 3] * d0)
        phi_f = (a_f - grid_bearing(px, py)) % 360.0
        phi_0 = (a_f - omega * span - q0) % 360.0
        sig = np.sqrt(np.maximum(P[:, 0, 0], P[:, 2, 2])) / np.maximum(dist, 1.0)
        band = np.minimum(3.0 * np.degrees(sig) + 3.0 * (sensor.sigma_bearing_deg or 0.0),
                          MAX_EDGE_DEG)
        crossed = phi_f < phi_0
        certain = crossed & (phi_f >= band) & (phi_0 <= 360.0 - band)
        possible = crossed | (phi_f > 360.0 - band) | (phi_0 < band)
        if r is None:
            return Looks(np.where(looked & possible, pd, 0.0), looked & certain & inside)
        out_pd = np.zeros(looked.size)
        out_pd[r] = np.where(possible, pd, 0.0)
        out_certain = np.zeros(looked.size, bool)
        out_certain[r] = certain & inside.take(r)
        return Looks(out_pd, out_certain)

    def _learned_reach(self, sid: int, scan: Scan, site: tuple[float, float],
                       px: np.ndarray, py: np.ndarray, dist: np.ndarray) -> np.ndarray:
        """Feed the frame's plots to the radar's reach (ground range and grid bearing from
        its site), then which leaves (at ``px, py`` from the site) lie within it: beyond
        it a leaf may still be updated by a plot, but a miss is not certain."""
        if len(scan):
            z = np.asarray(scan.z, float).reshape(-1, 2)
            dx, dy = z[:, 0] - site[0], z[:, 1] - site[1]
            self.reach.update(sid, scan.plot_times(), np.hypot(dx, dy), grid_bearing(dx, dy))
        return self.reach.within(sid, dist, grid_bearing(px, py))

    def arrays(self) -> dict[str, np.ndarray]:
        ids = sorted(self._last_end)
        return {"sensor": np.array(ids, np.int64),
                "end": np.array([self._last_end[i] for i in ids], float),
                **self.reach.arrays()}

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        self._last_end = {int(s): float(e) for s, e in
                          zip(arrays.get("sensor", []), arrays.get("end", []), strict=True)}
        if "reach_sensor" in arrays:  # a state saved before the learned reach has none
            self.reach.set_arrays(arrays)
