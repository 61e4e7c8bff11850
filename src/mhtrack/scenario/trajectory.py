"""Continuous-time truth: the targets' grid states joined by cubic Hermite curves.

A rotating radar sees a target at the moment its beam crosses it, at any time, while a
scenario gives each target's state ``[x, vx, y, vy]`` on the scan grid ``t_k = k·T``
(:func:`~mhtrack.scenario.simulate.simulate_truth`). Between two consecutive grid states
``(p0, v0)`` at ``t0`` and ``(p1, v1)`` at ``t1 = t0 + h`` the position is the cubic
Hermite curve through both positions *and* velocities (e.g. de Boor, *A Practical Guide to
Splines*, 2001, ch. IV), with ``s = (t − t0) / h``::

    p(t) = (2s³ − 3s² + 1) p0 + (s³ − 2s² + s) h v0 + (−2s³ + 3s²) p1 + (s³ − s²) h v1
    v(t) = dp/dt

It is exact for constant-velocity targets (a straight line at constant speed is a cubic),
keeps the recorded speeds of recorded trajectories, and has continuous velocity. A target
lives on the union of its *segments*: runs of consecutive scans (a recorded target with
a gap is absent between the two rows around the gap; a single isolated row is a segment
of zero length, seen by no rotating radar).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mhtrack.records import TruthTable


@dataclass(frozen=True)
class Segment:
    """One target's life between two grid states with no gap: grid times ``t`` (n,),
    positions ``p`` (n, 2) and velocities ``v`` (n, 2), ``n >= 1``."""

    target_id: int
    t: np.ndarray
    p: np.ndarray
    v: np.ndarray

    @property
    def start(self) -> float:
        return float(self.t[0])

    @property
    def end(self) -> float:
        return float(self.t[-1])

    def state(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Hermite position (n, 2) and velocity (n, 2) at times ``t`` (clipped to the
        segment; exactly the grid state at a grid time)."""
        t = np.clip(np.asarray(t, float).reshape(-1), self.start, self.end)
        if len(self.t) == 1:
            return np.repeat(self.p, len(t), axis=0), np.repeat(self.v, len(t), axis=0)
        i = np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, len(self.t) - 2)
        t0, h = self.t[i], self.t[i + 1] - self.t[i]
        s = ((t - t0) / h)[:, None]
        hh = h[:, None]
        p0, p1, v0, v1 = self.p[i], self.p[i + 1], self.v[i], self.v[i + 1]
        s2, s3 = s * s, s * s * s
        pos = ((2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * hh * v0
               + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * hh * v1)
        vel = ((6 * s2 - 6 * s) / hh * (p0 - p1) + (3 * s2 - 4 * s + 1) * v0
               + (3 * s2 - 2 * s) * v1)
        return pos, vel


def segments(truth: TruthTable) -> list[Segment]:
    """The :class:`Segment` s of a grid truth table (sorted by scan then id), in order of
    target id, then time."""
    out: list[Segment] = []
    order = np.lexsort((truth.scan, truth.target_id))
    tid, scan = truth.target_id[order], truth.scan[order]
    p = np.column_stack((truth.x, truth.y))[order]
    v = np.column_stack((truth.vx, truth.vy))[order]
    t = truth.time[order]
    cut = np.flatnonzero((np.diff(tid) != 0) | (np.diff(scan) != 1)) + 1
    for a, b in zip(np.concatenate(([0], cut)).tolist(),
                    np.concatenate((cut, [len(tid)])).tolist(), strict=True):
        if b > a:
            out.append(Segment(int(tid[a]), t[a:b], p[a:b], v[a:b]))
    return out


def sample_truth(segs: list[Segment], start: float, end: float, dt: float) -> TruthTable:
    """The truth every ``dt`` seconds from ``start`` to ``end`` (inclusive): sample ``j``
    at ``start + j·dt`` (``scan = j``), each target alive then with its Hermite state;
    sorted by sample, then target id."""
    n = int(np.floor((end - start) / dt + 1e-9)) + 1
    times = start + dt * np.arange(n)
    scans, ids, pos, vel = [], [], [], []
    for s in segs:
        j = np.flatnonzero((times >= s.start) & (times <= s.end))
        if j.size == 0:
            continue
        p, v = s.state(times[j])
        scans.append(j)
        ids.append(np.full(j.size, s.target_id, np.int64))
        pos.append(p)
        vel.append(v)
    if not scans:
        e = np.zeros(0)
        return TruthTable(np.zeros(0, np.int64), e, np.zeros(0, np.int64), e, e, e, e)
    scan, tid = np.concatenate(scans).astype(np.int64), np.concatenate(ids)
    p, v = np.concatenate(pos), np.concatenate(vel)
    o = np.lexsort((tid, scan))
    return TruthTable(scan=scan[o], time=times[scan[o]], target_id=tid[o],
                      x=np.ascontiguousarray(p[o, 0]), y=np.ascontiguousarray(p[o, 1]),
                      vx=np.ascontiguousarray(v[o, 0]), vy=np.ascontiguousarray(v[o, 1]))


def bridge_gaps(scans: np.ndarray, states: np.ndarray, period: float,
                max_gap_s: float) -> tuple[np.ndarray, np.ndarray]:
    """A recorded trajectory with its short gaps filled: at every missing grid scan of a
    gap of at most ``max_gap_s`` seconds between two rows, the Hermite state of the curve
    joining them (module docstring). ``scans`` (n,) increasing, ``states`` (n, 4) as
    ``[x, vx, y, vy]``; longer gaps stay gaps (the target is absent there)."""
    scans = np.asarray(scans, np.int64)
    states = np.asarray(states, float)
    new_scans, new_states = [scans], [states]
    for i in np.flatnonzero((np.diff(scans) > 1) & (np.diff(scans) * period <= max_gap_s)):
        t = np.array([scans[i], scans[i + 1]], float) * period
        seg = Segment(0, t, states[[i, i + 1]][:, [0, 2]], states[[i, i + 1]][:, [1, 3]])
        fill = np.arange(scans[i] + 1, scans[i + 1])
        pos, vel = seg.state(fill * period)
        new_scans.append(fill)
        new_states.append(np.column_stack((pos[:, 0], vel[:, 0], pos[:, 1], vel[:, 1])))
    sc = np.concatenate(new_scans)
    order = np.argsort(sc, kind="stable")
    return sc[order], np.concatenate(new_states)[order]
