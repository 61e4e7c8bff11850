"""A radar's reach learned from its own plots, for a sensors file without ``max_range``
(or with blind sectors it does not list): the range envelope per azimuth sector over the
radar's recent rotations (docs/mht.md, "Reach learned from the plots").

Estimator. The radar's azimuth is cut into ``S`` equal sectors; its time line into
rotations of its ``period`` (else of ``window`` s), numbered from its first plot; it
remembers the last ``K = ⌈memory / period⌉`` rotations. For rotation ``k`` and sector
``s``, ``m_k(s)`` is the largest ground range of its plots there (clutter included:
clutter is what shows where a radar sees when no aircraft is there). The reach of sector
``s`` is the ``rank``-th largest of ``m_k(s)`` over the last ``K`` rotations (empty
rotation-sectors count as 0):

    R(s) = rank-th largest of { m_k(s) : k_now − K < k ≤ k_now }.

A position at ground range ``r`` and azimuth ``θ`` is within reach when
``r ≤ (1 + margin) · max(R(s₋), R(s₊))``, ``s∓`` the sectors of ``θ ∓ ½`` sector width
(a target on a sector edge is judged by the more generous side).

Robust to: a single far false plot (second-time-around echo, a spurious plot at the
instrumented range) — with ``rank`` = 2 one outlier in ``K`` rotations does not extend
the reach; traffic that comes and goes (the envelope keeps ``K`` rotations); a reach that
changes (weather, a radar's mode): forgotten after ``K`` rotations. A sector with no plot
in the window (a blind sector, a masked one) has reach 0: no miss is charged there.
While a radar's memory holds fewer than ``rank`` rotations, the largest so far is used
(its first rotation gives a first envelope); before its first plot nothing is known and
every position is within reach (the former rule, an unlimited range).

Defaults, measured on ``opensky-radars`` seed 1 (three radars, 300 km, ~10–30 clutter
plots a rotation, uniform in range): the median over sectors of the reach at the end of
the run, for 16/32/64 sectors and a memory of 120/300/600 s — 16: 266–290/289–296/294–298
km; 32: 240–274/279–287/286–295; 64: 182–251/261–279/271–291 (the three radars). Sparse
clutter needs wide sectors and a long memory: 16 sectors (22.5°; a blind sector narrower
than that is not found) and 300 s. Margin 0: beyond the plots seen no miss is charged;
with ``max_range`` deleted, ids per aircraft were 0.0, 0.0, +1.0 % from the full sensors
file's on seeds 1–3 with margin 0, +3.0, +4.0, +6.0 % with 3 % and +21 % (seed 3) with
6 % (a margin charges misses beyond where the radar was seen to reach).

Streaming: ``K × S`` floats per radar; :meth:`ReachEstimator.update` per frame.
"""

from __future__ import annotations

import math

import numpy as np

#: Defaults: 16 sectors (22.5°), 300 s of memory, the 2nd largest, no margin, 10 s
#: rotations for a radar without a period.
SECTORS, MEMORY_S, RANK, MARGIN, WINDOW_S = 16, 300.0, 2, 0.0, 10.0


class ReachEstimator:
    """Each radar's reach per azimuth sector, learned online from its plots."""

    def __init__(self, periods: dict[int, float] | None = None, *, sectors: int = SECTORS,
                 memory: float = MEMORY_S, rank: int = RANK, margin: float = MARGIN,
                 window: float = WINDOW_S) -> None:
        if not (sectors >= 1 and rank >= 1 and memory > 0 and margin >= 0 and window > 0):
            raise ValueError(f"reach estimator: sectors {sectors}, memory {memory} s, "
                             f"rank {rank}, margin {margin}, window {window} s: need "
                             "sectors ≥ 1, rank ≥ 1, memory > 0, margin ≥ 0, window > 0")
        self.periods = {int(k): float(v) for k, v in (periods or {}).items() if v and v > 0}
        self.sectors, self.rank, self.memory = int(sectors), int(rank), float(memory)
        self.margin, self.window = float(margin), float(window)
        self.start: dict[int, float] = {}
        self.maxima: dict[int, np.ndarray] = {}  # (rotations, sectors)
        self.held: dict[int, np.ndarray] = {}  # the rotation each ring slot holds, or -1

    def rotations(self, sensor: int) -> int:
        """``K``: the rotations a radar's memory holds (at least ``rank``)."""
        period = self.periods.get(sensor, self.window)
        return max(self.rank, math.ceil(self.memory / period))

    def _sector(self, bearing: np.ndarray) -> np.ndarray:
        return (np.floor(np.mod(bearing, 360.0) / 360.0 * self.sectors).astype(np.int64)
                % self.sectors)

    def update(self, sensor: int, time: np.ndarray, dist: np.ndarray,
               bearing: np.ndarray) -> None:
        """Add a radar's plots: times (s), ground ranges from its site (m), azimuths
        (deg, clockwise from north), in time order across calls."""
        time, dist = np.asarray(time, float).ravel(), np.asarray(dist, float).ravel()
        bearing = np.asarray(bearing, float).ravel()
        ok = np.isfinite(time) & np.isfinite(dist) & np.isfinite(bearing)
        if not ok.any():
            return
        time, dist, bearing = time[ok], dist[ok], bearing[ok]
        period = self.periods.get(sensor, self.window)
        if sensor not in self.start:
            self.start[sensor] = float(time.min())
            k = self.rotations(sensor)
            self.maxima[sensor] = np.zeros((k, self.sectors))
            self.held[sensor] = np.full(k, -1, np.int64)
        rot = np.floor((time - self.start[sensor]) / period).astype(np.int64)
        rot = np.maximum(rot, 0)
        sector = self._sector(bearing)
        maxima, held = self.maxima[sensor], self.held[sensor]
        for k in np.unique(rot).tolist():
            slot = k % held.size
            if held[slot] != k:
                if held[slot] > k:  # a plot older than the window: nothing to learn
                    continue
                maxima[slot] = 0.0
                held[slot] = k
            mine = rot == k
            np.maximum.at(maxima[slot], sector[mine], dist[mine])

    def envelope(self, sensor: int) -> np.ndarray | None:
        """``R(s)`` per sector (m) — the ``rank``-th largest per-rotation maximum, or the
        largest while fewer rotations are held — or ``None`` before the radar's first
        plot."""
        held = self.held.get(sensor)
        if held is None:
            return None
        now = int(held.max())
        live = (held >= 0) & (held > now - held.size)
        return np.sort(self.maxima[sensor][live], axis=0)[-min(self.rank, int(live.sum()))]

    def within(self, sensor: int, dist: np.ndarray, bearing: np.ndarray) -> np.ndarray:
        """Whether positions at ground range ``dist`` (m) and azimuth ``bearing`` (deg) are
        within the radar's learned reach (all ``True`` while it is unknown)."""
        dist = np.asarray(dist, float)
        env = self.envelope(sensor)
        if env is None:
            return np.ones(dist.shape, bool)
        half = 180.0 / self.sectors
        b = np.asarray(bearing, float)
        reach = np.maximum(env[self._sector(b - half)], env[self._sector(b + half)])
        return dist <= (1.0 + self.margin) * reach

    def summary(self) -> dict[int, tuple[float, float, float]]:
        """Per radar ``(min, median, max)`` of its sectors' reach (m); NaN while unknown."""
        out = {}
        for sensor in sorted(self.held):
            env = self.envelope(sensor)
            out[sensor] = (math.nan,) * 3 if env is None else (
                float(env.min()), float(np.median(env)), float(env.max()))
        return out

    def arrays(self) -> dict[str, np.ndarray]:
        """The state as arrays (for a state file): sensors, starts, and each radar's
        rotations (``K``) of maxima and held rotation numbers, stacked."""
        ids = sorted(self.start)
        return {"reach_sensor": np.array(ids, np.int64),
                "reach_start": np.array([self.start[i] for i in ids], float),
                "reach_rotations": np.array([self.held[i].size for i in ids], np.int64),
                "reach_maxima": (np.concatenate([self.maxima[i] for i in ids]) if ids
                                 else np.zeros((0, self.sectors))),
                "reach_held": (np.concatenate([self.held[i] for i in ids]) if ids
                               else np.zeros(0, np.int64))}

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """Restore :meth:`arrays` (checked: a damaged state raises ``ValueError``)."""
        sensor = np.asarray(arrays["reach_sensor"])
        start = np.asarray(arrays["reach_start"], float)
        rotations = np.asarray(arrays["reach_rotations"])
        maxima = np.asarray(arrays["reach_maxima"])
        held = np.asarray(arrays["reach_held"])
        n = sensor.size
        if not (sensor.ndim == rotations.ndim == start.ndim == held.ndim == 1
                and sensor.dtype.kind in "iu" and rotations.dtype.kind in "iu"
                and held.dtype.kind in "iu" and start.size == rotations.size == n
                and np.unique(sensor).size == n and (rotations >= 1).all()
                and maxima.ndim == 2 and maxima.shape[1] == self.sectors
                and maxima.shape[0] == held.size == int(rotations.sum())
                and np.isfinite(start).all() and np.isfinite(maxima).all()
                and (maxima >= 0).all() and (held >= -1).all()):
            raise ValueError("the learned reach's arrays are inconsistent (sensors, starts, "
                             f"rotations, a (rotations, {self.sectors}) array of ranges ≥ 0 "
                             "and the rotation each row holds)")
        ids = [int(i) for i in sensor]
        if not ids:
            self.start, self.maxima, self.held = {}, {}, {}
            return
        cut = np.cumsum(rotations)[:-1]
        self.start = {i: float(t) for i, t in zip(ids, arrays["reach_start"], strict=True)}
        self.maxima = {i: np.array(m, float) for i, m in zip(
            ids, np.split(np.asarray(arrays["reach_maxima"]), cut), strict=True)}
        self.held = {i: np.array(h, np.int64) for i, h in zip(
            ids, np.split(np.asarray(arrays["reach_held"]), cut), strict=True)}
