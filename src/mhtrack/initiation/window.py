"""Sliding windows of ``N`` scans and what every initiator returns (P2 §2, §3.2).

A :class:`Window` stacks the plots of ``N`` consecutive scans (P2: ``N = 4``) into flat
arrays — positions, covariances, *slot* (0 … N−1, the scan's place in the window) and the
plot's index inside its scan — so that an initiator works on whole arrays.

An initiator returns :class:`InitiatedTracks`: one row per track with the index of its
plot in each scan of the window (``−1`` = no plot in that scan), and an initial state
``x = [x, vx, y, vy]`` with covariance ``P`` estimated from its plots by (generalised)
least squares on a straight line at constant velocity, at the time of the window's last
scan::

    z_s = H_s x + w_s,   H_s = [[1, t_s − t_N, 0, 0], [0, 0, 1, t_s − t_N]],   w_s ~ N(0, R_s)
    P = (Σ_s H_sᵀ R_s⁻¹ H_s)⁻¹,   x = P Σ_s H_sᵀ R_s⁻¹ z_s

(the weighted least-squares / batch estimate of Bar-Shalom et al. 2001 §3.4 without
process noise; ``R_s`` the plot's covariance, or ``default_R`` for plots without one).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from mhtrack.models.linalg2 import inv2
from mhtrack.records import Scan

NO_PLOT = -1
#: Covariance used for plots that carry none (Cartesian scans): (100 m)² I (P1's σw²).
DEFAULT_R = np.eye(2) * 100.0**2


@dataclass(frozen=True, slots=True)
class Window:
    """Plots of ``N`` consecutive scans, flattened.

    Attributes
    ----------
    scans : (N,) scan indices; times : (N,) scan times (s).
    z : (n, 2) positions; R : (n, 2, 2) covariances; slot : (n,) 0…N−1;
    index : (n,) index of the plot in its scan; origin : (n,) or None.
    start : (N + 1,) plots of slot ``s`` are ``start[s]:start[s+1]``.
    R_inv : (n, 2, 2) inverse covariances.
    t : (n,) each plot's own time (s) when the scans carry one (timed plots: the slots
        are a radar's rotations, ``times`` their nominal times); ``None``: every plot has
        its slot's time (P2's scans).
    """

    scans: np.ndarray
    times: np.ndarray
    z: np.ndarray
    R: np.ndarray
    slot: np.ndarray
    index: np.ndarray
    origin: np.ndarray | None
    start: np.ndarray
    R_inv: np.ndarray
    t: np.ndarray | None = None

    @property
    def n_scans(self) -> int:
        return len(self.scans)

    def __len__(self) -> int:
        return len(self.z)

    def rows(self, s: int) -> np.ndarray:
        """Flat indices of the plots of slot ``s``."""
        return np.arange(self.start[s], self.start[s + 1])

    def plot_times(self) -> np.ndarray:
        """(n,) each plot's time: ``t``, or its slot's time."""
        return self.times[self.slot] if self.t is None else self.t

    @classmethod
    def from_scans(cls, scans: Sequence[Scan], default_R: np.ndarray = DEFAULT_R) -> Window:
        """Stack ``scans`` (in time order) into a window; the plots' own times ``t`` when
        every scan has them (:attr:`Scan.t`)."""
        if len(scans) == 0:
            raise ValueError("a window needs at least one scan")
        times = np.array([s.time for s in scans], float)
        if np.any(np.diff(times) <= 0):
            raise ValueError("window scans must be in strictly increasing time")
        n = np.array([len(s) for s in scans], np.int64)
        z = np.concatenate([s.z for s in scans]).reshape(-1, 2).astype(float)
        R = np.concatenate(
            [s.R if s.R is not None else np.broadcast_to(default_R, (len(s), 2, 2))
             for s in scans]
        ).reshape(-1, 2, 2)
        has_o = all(s.origin is not None for s in scans)
        origin = (np.concatenate([s.origin for s in scans]).astype(np.int64)  # type: ignore[misc]
                  if has_o else None)
        return cls(
            scans=np.array([s.index for s in scans], np.int64),
            times=times,
            z=z,
            R=np.asarray(R, float),
            slot=np.repeat(np.arange(len(scans)), n),
            index=np.concatenate([np.arange(k) for k in n]).astype(np.int64),
            origin=origin,
            start=np.concatenate(([0], np.cumsum(n))).astype(np.int64),
            R_inv=inv2(np.asarray(R, float)),
            t=(np.concatenate([s.t for s in scans]).astype(float)  # type: ignore[misc]
               if all(s.t is not None for s in scans) else None),
        )


def sliding_windows(scans: Sequence[Scan], n_scans: int = 4) -> Iterator[list[Scan]]:
    """Every run of ``n_scans`` consecutive scans (P2: ``N = 4``), in order."""
    if n_scans < 1:
        raise ValueError(f"n_scans must be >= 1, got {n_scans}")
    for i in range(len(scans) - n_scans + 1):
        yield list(scans[i : i + n_scans])


@dataclass(frozen=True, slots=True)
class InitiatedTracks:
    """Tracks started in one window.

    ``plots[i, s]`` is the index (in scan ``scans[s]``'s plots) of track ``i``'s plot at
    that scan, ``−1`` when it has none; ``flat[i, s]`` the same as a flat
    :class:`Window` index. ``x`` (n, 4) and ``P`` (n, 4, 4): least-squares state at
    ``time`` (the window's last scan; module docstring).
    """

    scans: np.ndarray
    time: float
    plots: np.ndarray
    flat: np.ndarray
    x: np.ndarray
    P: np.ndarray

    def __len__(self) -> int:
        return len(self.plots)

    def origins(self, window: Window) -> np.ndarray:
        """(n, N) origin of each track's plot per scan (``−2`` where it has none)."""
        if window.origin is None:
            raise ValueError("the window's plots have no origin")
        o = window.origin[np.maximum(self.flat, 0)]
        return np.where(self.flat >= 0, o, -2)


def least_squares_state(
    window: Window, flat: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Straight-line GLS state ``x`` and covariance ``P`` at the last scan of ``window``
    for tracks given by flat plot indices ``flat`` (n, N) (module docstring).

    With ``W_s = R_s⁻¹`` (0 on a miss) and ``τ_s = t_s − t_N`` (``t_s`` the plot's own
    time when the window has them, :attr:`Window.t`) the normal equations split
    into 2×2 blocks: ``A_m = Σ τ_s^m W_s`` (m = 0, 1, 2) and ``b_m = Σ τ_s^m W_s z_s``;
    ``info = [[A0, A1], [A1, A2]]`` over (position, velocity), inverted blockwise through
    the Schur complement ``A2 − A1 A0⁻¹ A1`` and permuted to ``[x, vx, y, vy]``."""
    flat = np.asarray(flat, np.int64).reshape(-1, window.n_scans)
    n = len(flat)
    if n == 0:
        return np.zeros((0, 4)), np.zeros((0, 4, 4))
    have = flat >= 0
    idx = np.maximum(flat, 0)
    W = window.R_inv[idx] * have[..., None, None]  # (n, N, 2, 2)
    Wz = np.einsum("nsab,nsb->nsa", W, window.z[idx])
    if window.t is None:
        tau = window.times - window.times[-1]
        A0, A1, A2 = (np.tensordot(W, tau**m, axes=([1], [0])) for m in range(3))  # (n,2,2)
        b0, b1 = (np.tensordot(Wz, tau**m, axes=([1], [0])) for m in range(2))  # (n, 2)
    else:  # each plot at its own time
        tau_p = np.where(have, window.t[idx] - window.times[-1], 0.0)  # (n, N)
        A0, A1, A2 = (np.einsum("nsab,ns->nab", W, tau_p**m) for m in range(3))
        b0, b1 = (np.einsum("nsa,ns->na", Wz, tau_p**m) for m in range(2))
    # block inverse of [[A0, A1], [A1, A2]] (A1 symmetric) by the Schur complement
    A0i = inv2(A0)
    G = A0i @ A1
    Pvv = inv2(A2 - A1 @ G)
    Ppv = -G @ Pvv
    Ppp = A0i - Ppv @ G.transpose(0, 2, 1)
    P = np.empty((n, 4, 4))
    pos, vel = [0, 2], [1, 3]
    P[:, 0::2, 0::2] = Ppp
    P[:, 0::2, 1::2] = Ppv
    P[:, 1::2, 0::2] = Ppv.transpose(0, 2, 1)
    P[:, 1::2, 1::2] = Pvv
    x = np.empty((n, 4))
    x[:, pos] = np.einsum("nij,nj->ni", Ppp, b0) + np.einsum("nij,nj->ni", Ppv, b1)
    x[:, vel] = np.einsum("nji,nj->ni", Ppv, b0) + np.einsum("nij,nj->ni", Pvv, b1)
    return x, 0.5 * (P + np.swapaxes(P, 1, 2))


def last_slot(path: np.ndarray) -> np.ndarray:
    """Slot of each row's last plot (rows of flat indices, ``−1`` = no plot)."""
    return path.shape[1] - 1 - np.argmax((path >= 0)[:, ::-1], axis=1)


def previous_plot(path: np.ndarray) -> np.ndarray:
    """Flat index of each row's second-to-last plot (``−1`` when it has one plot)."""
    on = path >= 0
    rank = np.cumsum(on[:, ::-1], axis=1)[:, ::-1] * on  # 1 = last plot, 2 = previous …
    has = (rank == 2).any(axis=1)
    s = np.argmax(rank == 2, axis=1)
    return np.where(has, path[np.arange(len(path)), s], NO_PLOT)


def _row_keys(rows: np.ndarray, base: int) -> np.ndarray | None:
    """Integer key per row (``Σ (v+1)·base^s``) when it fits in int64, else None."""
    N = rows.shape[1]
    if N * np.log2(max(base, 2)) >= 62:
        return None
    w = base ** np.arange(N, dtype=np.int64)
    return (rows + 1) @ w


def remove_dominated(flat: np.ndarray) -> np.ndarray:
    """Rows of ``flat`` (n, N; ``−1`` = no plot) to keep: drop duplicate rows and every
    track whose plots are all in another track (a strict sub-track: the same plots at the
    same scans, fewer of them). Returns a boolean mask; the first of duplicates is kept."""
    flat = np.asarray(flat, np.int64)
    n, N = flat.shape
    if n == 0:
        return np.zeros(0, bool)
    base = int(flat.max()) + 2
    key = _row_keys(flat, base)
    if key is None:  # huge windows: compare rows through np.unique
        _, key = np.unique(flat, axis=0, return_inverse=True)
        key = key.reshape(-1)
        fits = False
    else:
        fits = True
    _, first = np.unique(key, return_index=True)
    keep = np.zeros(n, bool)
    keep[first] = True
    hits = (flat >= 0).sum(axis=1)
    lowest = int(hits.min())
    # strict sub-tracks of the longer tracks, one plot dropped at a time, down to the
    # fewest plots any track has (N is small: few sub-tracks per track)
    subs = []
    level = flat[hits > lowest]
    while len(level):
        parts = []
        for s in range(N):
            d = level[level[:, s] >= 0].copy()
            d[:, s] = NO_PLOT
            parts.append(d)
        level = np.concatenate(parts)
        subs.append(level)
        level = level[(level >= 0).sum(axis=1) > lowest]
    if not subs:
        return keep
    sub = np.concatenate(subs)
    if fits:
        sub_key = _row_keys(sub, base)
        keep &= ~np.isin(key, sub_key)
    else:
        _, inv = np.unique(np.concatenate((sub, flat)), axis=0, return_inverse=True)
        inv = inv.reshape(-1)
        keep &= ~np.isin(inv[len(sub):], inv[: len(sub)])
    return keep
