"""P2's initiators as the MHT's birth process (``logic``, ``modified-logic``, ``hough``,
``modified-hough``; P2 §2–3, ``docs/mht.md``).

The tracker keeps a sliding window of the last ``N = 4`` scans' plots, runs the P2
initiator on it every scan, and starts a tree only for each initiated track that has a plot
at the current scan and that no existing leaf already follows.

Window contents. The current scan enters with all its plots; once the scan's best global
hypothesis is known, the plots used by the chosen leaves of *confirmed* tracks are removed
from every scan of the window (:meth:`InitiatorBirth.forget_used`), so a target that is
already tracked is not initiated again, while plots of tentative trees stay available.
During the first ``N − 1`` scans a shorter window of ``n ≥ M = 3`` scans is used (3-of-3
logic; Hough with ``min(votes, n)`` votes), so a target present from the start is born at
the third scan.

Seeding. A new tree's leaf gets the initiator's least-squares state and covariance at the
current scan (:func:`~mhtrack.initiation.window.least_squares_state`), and its window
columns hold the initiated plots (row ids) at the scans the leaf window covers, so the
global hypothesis sees the plots it used and no plot is used twice. Its score is the
sequence's log-likelihood ratio (:func:`~mhtrack.mht.births.sequence.sequence_score`).

Deduplication. An initiated track is dropped when an existing leaf (after this scan's
growth) has, at every scan where the track has a plot and the leaf window reaches, that
same plot (:func:`followed_by`), and when two initiated tracks map to the same leaf window.

Everything is stored in arrays (:meth:`InitiatorBirth.arrays`), saved with the tracker.
"""

from __future__ import annotations

import numpy as np

from mhtrack.initiation import Initiator
from mhtrack.initiation.factory import make_initiator
from mhtrack.initiation.window import Window
from mhtrack.mht.births.base import Birth, BirthCandidates
from mhtrack.mht.births.sequence import score_upper_bound, sequence_score
from mhtrack.mht.context import FrameContext
from mhtrack.mht.pruning import cap_leaves_per_tree, score_drop_keep
from mhtrack.models.motion import MotionModel
from mhtrack.names import INITIATORS
from mhtrack.records import Scan

NO_PLOT = -1


def followed_by(cand: np.ndarray, leaves: np.ndarray) -> np.ndarray:
    """Mask of candidate windows (n, W) followed by some leaf window (m, W): a leaf with
    the same plot at every column where the candidate has one. Candidates must have a plot
    in the last column (only leaves with that plot are compared)."""
    n = len(cand)
    out = np.zeros(n, bool)
    if n == 0 or len(leaves) == 0:
        return out
    order = np.argsort(leaves[:, -1], kind="stable")
    last = leaves[order, -1]
    lo = np.searchsorted(last, cand[:, -1], "left")
    hi = np.searchsorted(last, cand[:, -1], "right")
    k = hi - lo
    if k.sum() == 0:
        return out
    ci = np.repeat(np.arange(n), k)
    li = order[np.repeat(lo - np.cumsum(k) + k, k) + np.arange(int(k.sum()))]
    c = cand[ci]
    ok = ((c < 0) | (leaves[li] == c)).all(axis=1)
    out[ci[ok]] = True
    return out


class InitiatorBirth(Birth):
    """A P2 initiator over a sliding window of the last ``n_scans`` scans as the MHT's
    birth process (module docstring).

    Parameters
    ----------
    method : ``"logic"``, ``"modified-logic"``, ``"hough"`` or ``"modified-hough"``.
    motion : the tracker's motion model (filter and plot likelihood of the score).
    theta_deg : angle limit of the modified methods (P2: 20°).
    width : columns of the leaf window (``n_scan + 1``).
    p_detection, new_target_density, miss_dl, v_max : the tracker's scoring and
        initialisation parameters (:func:`~mhtrack.mht.births.sequence.sequence_score`).
    floor : initiated tracks scoring ``L ≤ floor`` are not born (the tracker passes its
        SPRT deletion threshold ``ln(β/(1−α))``: Wald's lower test on the sequence).
    max_per_scan : most initiated tracks proposed per scan (highest scores, then
        initiator order).
    prune_drop, max_leaves_per_tree : a new tree's leaves are pruned as children are
        (score drop within the tree, leaves per tree).
    n_scans, min_plots : window ``N`` and plots ``M`` (P2: 4, 3).
    """

    def __init__(self, method: str, motion: MotionModel, *, theta_deg: float, width: int,
                 p_detection: float, new_target_density: float, miss_dl: float,
                 v_max: float, floor: float, max_per_scan: int, prune_drop: float,
                 max_leaves_per_tree: int, n_scans: int = 4, min_plots: int = 3) -> None:
        if method not in INITIATORS:
            raise ValueError(f"unknown initiator birth {method!r}")
        super().__init__(motion)
        self.method = method
        self.theta_deg = float(theta_deg)
        self.width = width
        self.n_scans = n_scans
        self.min_plots = min_plots
        self.floor = float(floor)
        self.max_per_scan = max_per_scan
        self.prune_drop = prune_drop
        self.max_leaves_per_tree = max_leaves_per_tree
        self._score_params = dict(p_detection=p_detection,
                                  new_target_density=new_target_density, miss_dl=miss_dl,
                                  v_max=v_max, motion=motion)
        # the window: per scan index, time, plot count; per plot z, R, row id, κ̂
        self.scan_index = np.zeros(0, np.int64)
        self.scan_time = np.zeros(0)
        self.count = np.zeros(0, np.int64)
        self.z = np.zeros((0, 2))
        self.R = np.zeros((0, 2, 2))
        self.rows = np.zeros(0, np.int64)
        self.kappa = np.zeros(0)

    def _initiator(self, n: int) -> Initiator:
        if self.method.endswith("logic"):
            return make_initiator(self.method, theta_deg=self.theta_deg, n_scans=n,
                                  min_plots=self.min_plots)
        return make_initiator(self.method, theta_deg=self.theta_deg, n_scans=n,
                              votes=min(4, n))

    # ------------------------------------------------------------------ window
    def _push(self, index: int, time: float, z: np.ndarray, R: np.ndarray,
              rows: np.ndarray, kappa: np.ndarray) -> None:
        R = np.broadcast_to(R, (len(z), 2, 2)) if R.ndim == 2 else R
        self.scan_index = np.append(self.scan_index, np.int64(index))
        self.scan_time = np.append(self.scan_time, float(time))
        self.count = np.append(self.count, np.int64(len(z)))
        self.z = np.concatenate((self.z, z))
        self.R = np.concatenate((self.R, R))
        self.rows = np.concatenate((self.rows, rows.astype(np.int64)))
        self.kappa = np.concatenate((self.kappa, kappa))
        drop = len(self.count) - self.n_scans
        if drop > 0:
            cut = int(self.count[:drop].sum())
            self.scan_index, self.scan_time = self.scan_index[drop:], self.scan_time[drop:]
            self.count = self.count[drop:]
            self.z, self.R = self.z[cut:], self.R[cut:]
            self.rows, self.kappa = self.rows[cut:], self.kappa[cut:]

    def _slot(self) -> np.ndarray:
        return np.repeat(np.arange(len(self.count)), self.count)

    def forget_used(self, window: np.ndarray) -> None:
        """Remove from the window the plots in ``window`` (m, width): the leaf windows
        of the confirmed tracks' chosen leaves at the current scan."""
        if len(window) == 0 or len(self.rows) == 0:
            return
        m = len(self.count)
        slot = self._slot()
        keep = np.ones(len(self.rows), bool)
        for s in range(m):
            c = self.width - m + s  # leaf column of the scan (< 0: older than the leaves)
            if c < 0:
                continue
            at = slot == s
            keep[at] = ~np.isin(self.rows[at], window[:, c][window[:, c] >= 0])
        if keep.all():
            return
        self.count = np.bincount(slot[keep], minlength=m).astype(np.int64)
        self.z, self.R = self.z[keep], self.R[keep]
        self.rows, self.kappa = self.rows[keep], self.kappa[keep]

    # ------------------------------------------------------------------ births
    def limit(self, max_per_scan: int) -> None:
        self.max_per_scan = int(max_per_scan)

    def propose(self, frame: FrameContext, kappa: np.ndarray,
                in_gates: np.ndarray | None) -> BirthCandidates:
        """The initiated tracks with a plot at this scan (:meth:`initiate`); over
        ``max_per_scan``, the highest birth scores (then initiator order)."""
        cand = self.initiate(frame, kappa)
        cap = self.max_per_scan
        if len(cand) > cap:
            frame.cut("max_births_per_scan", len(cand) - cap)
            cand = cand.take(np.sort(np.argsort(-cand.score, kind="stable")[:cap]))
        return cand

    def initiate(self, frame: FrameContext, kappa: np.ndarray) -> BirthCandidates:
        """Add the frame's plots to the window, run the initiator and return the initiated
        tracks that have a plot at this scan, seeded and scored (module docstring)."""
        scan, z, R, rows = frame.scan, frame.z, frame.R, frame.rows
        self._push(int(scan.index), float(scan.time), z, R, rows, kappa)
        m = len(self.count)
        if m < self.min_plots or self.count[-1] == 0:
            return BirthCandidates.empty(self.width)
        start = np.concatenate(([0], np.cumsum(self.count)))
        scans = [Scan(int(self.scan_index[s]), float(self.scan_time[s]),
                      self.z[start[s]:start[s + 1]],
                      np.zeros(int(self.count[s]), np.int64),
                      self.rows[start[s]:start[s + 1]], self.R[start[s]:start[s + 1]])
                 for s in range(m)]
        w = Window.from_scans(scans)
        tracks = self._initiator(m).initiate(w)
        flat = tracks.flat
        sel = flat[:, -1] >= 0  # a plot at the current scan
        if not sel.any():
            return BirthCandidates.empty(self.width)
        flat = flat[sel]
        has = flat >= 0
        idx = np.maximum(flat, 0)  # Window flat order == the stored plot order
        sp = self._score_params
        bound = score_upper_bound(has, self.R[idx], self.kappa[idx],
                                  p_detection=sp["p_detection"],
                                  new_target_density=sp["new_target_density"],
                                  miss_dl=sp["miss_dl"])
        ok = np.flatnonzero(bound > self.floor)
        sel = np.flatnonzero(sel)[ok]
        flat, has, idx = flat[ok], has[ok], idx[ok]
        score, peak = sequence_score(self.scan_time, self.z[idx], self.R[idx], has,
                                     self.kappa[idx], **sp)
        ok = np.flatnonzero(score > self.floor)
        sel, flat, has, idx, score, peak = sel[ok], flat[ok], has[ok], idx[ok], score[ok], peak[ok]
        x, P = tracks.x[sel], tracks.P[sel]
        rows_seq = np.where(has, self.rows[idx], NO_PLOT)
        window = np.full((len(flat), self.width), NO_PLOT, np.int64)
        k = min(m, self.width)
        window[:, self.width - k:] = rows_seq[:, m - k:]
        return BirthCandidates(x, P, score, peak, window, has.sum(axis=1).astype(np.int64))

    def select(self, frame: FrameContext, cand: BirthCandidates,
               leaf_window: np.ndarray) -> tuple[BirthCandidates, np.ndarray]:
        """Drop candidates already followed by a leaf and repeats of one leaf window, group
        the rest by their plot at the current scan — one new tree per group (module
        docstring) — and prune each group as children are (score drop, leaves per tree):
        ``(candidates sorted by group, group index)``."""
        cand, group = self._group(cand, leaf_window)
        keep = score_drop_keep(group, cand.score, self.prune_drop)
        cand, group = cand.take(keep), group[keep]
        keep, cut = cap_leaves_per_tree(group, cand.score, self.max_leaves_per_tree)
        if cut:
            frame.cut("max_leaves_per_tree", cut)
            cand, group = cand.take(keep), group[keep]
        return cand, group

    def _group(self, cand: BirthCandidates, leaf_window: np.ndarray
               ) -> tuple[BirthCandidates, np.ndarray]:
        if len(cand) == 0:
            return cand, np.zeros(0, np.int64)
        keep = ~self._followed(cand.window, leaf_window)
        _, first = np.unique(cand.window, axis=0, return_index=True)
        uniq = np.zeros(len(cand), bool)
        uniq[first] = True
        cand = cand.take(np.flatnonzero(keep & uniq))
        last = cand.window[:, -1]
        order = np.argsort(last, kind="stable")
        cand = cand.take(order)
        _, group = np.unique(last[order], return_inverse=True)
        return cand, group.reshape(-1).astype(np.int64)

    def _followed(self, cand: np.ndarray, leaves: np.ndarray) -> np.ndarray:
        """Candidates an existing leaf already follows (:func:`followed_by`)."""
        return followed_by(cand, leaves)

    # ------------------------------------------------------------------ persistence
    def arrays(self) -> dict[str, np.ndarray]:
        """The window as arrays (saved by the tracker as ``birth__*``)."""
        return {"scan_index": self.scan_index, "scan_time": self.scan_time,
                "count": self.count, "z": self.z, "R": self.R, "rows": self.rows,
                "kappa": self.kappa}

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        self.scan_index = np.asarray(arrays["scan_index"], np.int64)
        self.scan_time = np.asarray(arrays["scan_time"], float)
        self.count = np.asarray(arrays["count"], np.int64)
        self.z = np.asarray(arrays["z"], float).reshape(-1, 2)
        self.R = np.asarray(arrays["R"], float).reshape(-1, 2, 2)
        self.rows = np.asarray(arrays["rows"], np.int64)
        self.kappa = np.asarray(arrays["kappa"], float)
