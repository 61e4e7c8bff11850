"""P2's initiators on asynchronous plots: one window **per radar, in its rotations**
(``docs/mht.md``, *Birth processes*; issue 28, item 7).

A frame of timed plots is one radar's plots over at most an eighth of its rotation
(:mod:`mhtrack.frames`), and several radars interleave, so the last ``N = 4`` frames hold
about a second of plots from three radars: a target has one plot in them, rarely the 3 of
4 that P2's logic needs (measured on ``opensky-radars`` seed 1, first 600 frames: windows
of 1.0 s median, 1.8 s at most; of 3 484 windows holding a target seen at the current
frame, 2 741 held one of its plots, 694 two, 49 three; 4 tracks initiated; ``--birth
logic`` then followed 12 % of the aircraft). P2's "scan" is one look of a sensor at a target (its
§3 simulates radars with one common period; after P2 §1's clustering the initiation is a
single sensor's): the look of a rotating radar at a target comes once per rotation. So the
window of a frame of radar ``s`` (period ``T``, plots at ``t₀ … t_f``) is that radar's own
plots at the same azimuths over its last ``N`` rotations:

* slot ``N − 1`` (current): the frame's plots; slot ``N − 1 − j`` (``j = 1 … N − 1``):
  radar ``s``'s plots with ``t₀ − jT − m ≤ t < t_f − jT + m``, nominal time ``t_f − jT``,
  margin ``m = (T − (t_f − t₀))/4`` (a quarter of the rest of the rotation: the slots never
  overlap, and a target's bearing may drift by up to ~80° per rotation);
* every plot keeps its own time: the initiator's gates, the least-squares state (at
  ``t_f``) and the birth score (:func:`~mhtrack.mht.births.sequence.sequence_score`, each
  prediction to the plot's time; a miss at its slot's nominal time) use it;
* the score uses the frame's radar's ``P_D`` (``Coverage.plot_pd``), as every-plot births do;
* a sensor without a period (not rotating) takes its frame length (``DEFAULT_FRAME_S``)
  as ``T``: its slots are its last frames;
* the plots of confirmed tracks leave the store by plot id (a tree's window columns are its
  own looks, of every radar, so they do not line up with one radar's slots), and an
  initiated track is dropped when a leaf already holds its last two plots (``followed``).

The history kept is each radar's last ``N`` rotations plus a margin; everything is in
arrays, saved with the tracker (:meth:`TimedInitiatorBirth.arrays`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from mhtrack.frames import DEFAULT_FRAME_S
from mhtrack.initiation import Initiator
from mhtrack.initiation.factory import make_initiator
from mhtrack.initiation.window import Window
from mhtrack.mht.births.base import BirthCandidates
from mhtrack.mht.births.initiator import NO_PLOT, InitiatorBirth
from mhtrack.mht.births.sequence import score_upper_bound, sequence_score
from mhtrack.mht.context import FrameContext
from mhtrack.mht.scoring import miss_increment
from mhtrack.models.motion import MotionModel
from mhtrack.records import Scan


def rotation_slots(t: np.ndarray, t0: float, tf: float, period: float, n_slots: int
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Slot of each of a radar's earlier plot times ``t`` in the window of its frame
    ``[t0, tf]`` (module docstring): ``(slot (n,), −1 outside every slot; nominal times
    (n_slots,))``. Slot ``n_slots − 1`` is the frame itself and takes no earlier plot."""
    m = 0.25 * max(period - (tf - t0), 0.0)
    slot = np.full(len(t), -1, np.int64)
    for j in range(1, n_slots):
        at = (t >= t0 - j * period - m) & (t < tf - j * period + m)
        slot[at] = n_slots - 1 - j
    nominal = tf - period * np.arange(n_slots - 1, -1, -1, dtype=float)
    return slot, nominal


def followed(cand: np.ndarray, leaves: np.ndarray) -> np.ndarray:
    """Mask of candidate windows (n, W) whose last two plots (any columns) some leaf window
    (m, W) holds, in any of its columns (a tree's columns are its own looks). Candidates
    must have a plot in the last column; the leaves holding it are found by a sorted
    search, so no (n, m) array is built."""
    n = len(cand)
    out = np.zeros(n, bool)
    if n == 0 or len(leaves) == 0:
        return out
    on = cand >= 0
    rank = np.cumsum(on[:, ::-1], axis=1)[:, ::-1] * on  # 1 = last plot, 2 = previous
    prev = np.where((rank == 2).any(axis=1), cand[np.arange(n), np.argmax(rank == 2, axis=1)],
                    NO_PLOT)
    li, col = np.nonzero(leaves >= 0)
    pid = leaves[li, col]
    order = np.argsort(pid, kind="stable")
    pid, li = pid[order], li[order]
    lo = np.searchsorted(pid, cand[:, -1], "left")
    k = np.searchsorted(pid, cand[:, -1], "right") - lo
    ci = np.repeat(np.arange(n), k)
    lj = li[np.repeat(lo - np.cumsum(k) + k, k) + np.arange(int(k.sum()))]
    ok = (prev[ci] < 0) | (leaves[lj] == prev[ci, None]).any(axis=1)
    out[ci[ok]] = True
    return out


class TimedInitiatorBirth(InitiatorBirth):
    """A P2 initiator over each radar's last ``n_scans`` rotations (module docstring).

    Parameters as :class:`~mhtrack.mht.births.initiator.InitiatorBirth`, and
    ``periods``: rotation period (s) per sensor id (``None``: not rotating);
    ``plot_pd``: the ``P_D`` of a frame's radar; ``gate_probability``: ``P_G`` of the
    miss increment ``ln(1 − P_D·P_G)`` (``None``: ``ln(1 − P_D)``, P1); ``gate_chi2``: the
    logic's χ² position gate on plot covariances (:class:`~mhtrack.initiation.LogicInitiator`)."""

    def __init__(self, method: str, motion: MotionModel, *, periods: Mapping[int, float | None],
                 plot_pd: Callable[[Scan], float], gate_probability: float | None,
                 gate_chi2: float | None = None, **params: Any) -> None:
        super().__init__(method, motion, **params)
        self.gate_chi2 = gate_chi2
        self.periods = {int(k): (DEFAULT_FRAME_S if p is None else float(p))
                        for k, p in periods.items()}
        self.plot_pd = plot_pd
        self.gate_probability = gate_probability
        self.t = np.zeros(0)
        self.sensor = np.zeros(0, np.int64)

    def _initiator(self, n: int) -> Initiator:
        if self.method.endswith("logic"):
            return make_initiator(self.method, theta_deg=self.theta_deg, n_scans=n,
                                  min_plots=self.min_plots, gate_chi2=self.gate_chi2)
        return make_initiator(self.method, theta_deg=self.theta_deg, n_scans=n, votes=n)

    def _period(self, sid: int) -> float:
        return self.periods.get(sid, DEFAULT_FRAME_S)

    # ------------------------------------------------------------------ store
    def _store(self, sid: int, t: np.ndarray, z: np.ndarray, R: np.ndarray,
               rows: np.ndarray, kappa: np.ndarray) -> None:
        """Add a frame's plots; forget each radar's plots older than ``N + 1`` rotations."""
        R = np.broadcast_to(R, (len(z), 2, 2)) if R.ndim == 2 else R
        self.t = np.concatenate((self.t, t))
        self.sensor = np.concatenate((self.sensor, np.full(len(z), sid, np.int64)))
        self.z = np.concatenate((self.z, z))
        self.R = np.concatenate((self.R, R))
        self.rows = np.concatenate((self.rows, rows.astype(np.int64)))
        self.kappa = np.concatenate((self.kappa, kappa))
        ids, inv = np.unique(self.sensor, return_inverse=True)
        horizon = np.array([self._period(int(s)) for s in ids])[inv] * (self.n_scans + 1)
        keep = self.t >= (t.max() if len(t) else -np.inf) - horizon
        if not keep.all():
            self._keep(keep)

    def _keep(self, keep: np.ndarray) -> None:
        self.t, self.sensor = self.t[keep], self.sensor[keep]
        self.z, self.R = self.z[keep], self.R[keep]
        self.rows, self.kappa = self.rows[keep], self.kappa[keep]

    def forget_used(self, window: np.ndarray) -> None:
        """Remove from the store the plots (by id) of the confirmed tracks' leaf windows."""
        if len(window) == 0 or len(self.rows) == 0:
            return
        keep = ~np.isin(self.rows, window[window >= 0])
        if not keep.all():
            self._keep(keep)

    # ------------------------------------------------------------------ births
    def initiate(self, frame: FrameContext, kappa: np.ndarray) -> BirthCandidates:
        """Store the frame's plots, run the initiator on its radar's window (module
        docstring) and return the initiated tracks with a plot in this frame, seeded at
        the frame's time and scored with the radar's ``P_D``."""
        scan, z, R, rows = frame.scan, frame.z, frame.R, frame.rows
        empty = BirthCandidates.empty(self.width)
        if len(z) == 0:
            return empty
        sid = int(scan.sensor[0])
        t_now = scan.plot_times().astype(float)
        self._store(sid, t_now, z, R, rows, kappa)
        earlier = np.flatnonzero(self.sensor[:len(self.t) - len(z)] == sid)
        period, N = self._period(sid), self.n_scans
        t0, tf = float(t_now.min()), float(scan.time)
        slot, nominal = rotation_slots(self.t[earlier], t0, tf, period, N)
        cur = np.arange(len(self.t) - len(z), len(self.t))
        parts = [earlier[slot == s] for s in range(N - 1)] + [cur]
        idx_all = np.concatenate(parts)
        scans = [Scan(s, float(nominal[s]), self.z[p], np.full(len(p), sid, np.int64),
                      self.rows[p], self.R[p], None, self.t[p]) for s, p in enumerate(parts)]
        w = Window.from_scans(scans)
        tracks = self._initiator(N).initiate(w)
        flat = tracks.flat
        sel = flat[:, -1] >= 0
        if not sel.any():
            return empty
        flat = flat[sel]
        has = flat >= 0
        idx = idx_all[np.maximum(flat, 0)]
        pd = float(self.plot_pd(scan))
        miss_dl = miss_increment(pd, self.gate_probability)
        sp = dict(self._score_params, p_detection=pd, miss_dl=miss_dl)
        bound = score_upper_bound(has, self.R[idx], self.kappa[idx], p_detection=pd,
                                  new_target_density=sp["new_target_density"],
                                  miss_dl=miss_dl)
        ok = np.flatnonzero(bound > self.floor)
        sel = np.flatnonzero(sel)[ok]
        flat, has, idx = flat[ok], has[ok], idx[ok]
        times = np.where(has, self.t[idx], nominal[None, :])
        score, peak = sequence_score(times, self.z[idx], self.R[idx], has, self.kappa[idx],
                                     **sp)
        ok = np.flatnonzero(score > self.floor)
        sel, has, idx, score, peak = sel[ok], has[ok], idx[ok], score[ok], peak[ok]
        rows_seq = np.where(has, self.rows[idx], NO_PLOT)
        window = np.full((len(sel), self.width), NO_PLOT, np.int64)
        k = min(N, self.width)
        window[:, self.width - k:] = rows_seq[:, N - k:]
        return BirthCandidates(tracks.x[sel], tracks.P[sel], score, peak, window,
                               has.sum(axis=1).astype(np.int64))

    def _followed(self, cand: np.ndarray, leaves: np.ndarray) -> np.ndarray:
        return followed(cand, leaves)

    # ------------------------------------------------------------------ persistence
    def arrays(self) -> dict[str, np.ndarray]:
        """The store as arrays (saved by the tracker as ``birth__*``)."""
        return {"t": self.t, "sensor": self.sensor, "z": self.z, "R": self.R,
                "rows": self.rows, "kappa": self.kappa}

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        self.t = np.asarray(arrays["t"], float)
        self.sensor = np.asarray(arrays["sensor"], np.int64)
        self.z = np.asarray(arrays["z"], float).reshape(-1, 2)
        self.R = np.asarray(arrays["R"], float).reshape(-1, 2, 2)
        self.rows = np.asarray(arrays["rows"], np.int64)
        self.kappa = np.asarray(arrays["kappa"], float)
