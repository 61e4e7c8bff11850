"""Starting mixtures for EM (:mod:`mhtrack.clutter.em`): k-means++ seeds among the plots
(Arthur & Vassilvitskii 2007), then one hard assignment and one M-step."""

from __future__ import annotations

import numpy as np

from mhtrack.clutter.em import Mixture
from mhtrack.kernels import cov_biased

_EYE2 = np.eye(2)
#: Scans whose generators :class:`ScanRngs` makes together. Setting one up is mostly
#: cold-cache time when made alone in a tracker's cycle (~47 µs), ~14 µs each made in a row
#: (docs/performance.md).
RNG_BATCH = 8


class ScanRngs:
    """Scan ``u``'s generator ``default_rng(SeedSequence(seed, spawn_key=(u,)))``, made
    ``RNG_BATCH`` scans ahead and handed out once each: a generator is a function of
    ``(seed, u)`` alone and none is drawn from before it is handed out, so the draws are
    those of one made when needed."""

    def __init__(self) -> None:
        self._ahead: dict[tuple[int, int], np.random.Generator] = {}

    def take(self, seed: int, u: int) -> np.random.Generator:
        """The fresh generator of scan ``u`` (``seed``)."""
        g = self._ahead.pop((seed, u), None)
        if g is None:
            self._ahead = {(seed, v): np.random.default_rng(np.random.SeedSequence(
                seed, spawn_key=(v,))) for v in range(u, u + RNG_BATCH)}
            g = self._ahead.pop((seed, u))
        return g


def kmeanspp_centres(
    z: np.ndarray, k: int, rng: np.random.Generator, existing: np.ndarray | None = None
) -> np.ndarray:
    """Up to ``k`` new centres drawn from the rows of ``z`` by k-means++ ``D²`` sampling
    (Arthur & Vassilvitskii 2007; the first one uniformly unless ``existing`` centres are
    given, to which distances are then measured). Stops early when every remaining plot
    sits on a centre (``D² = 0``), so identical plots give one centre."""
    chosen: list[np.ndarray] = []
    if existing is not None and len(existing):
        d2 = ((z[:, None, :] - existing[None, :, :]) ** 2).sum(axis=2).min(axis=1)
    else:
        first = z[int(rng.integers(len(z)))]
        chosen.append(first)
        d2 = ((z - first) ** 2).sum(axis=1)
    while len(chosen) < k:
        total = d2.sum()
        if not total > 0:
            break
        i = int(d2.cumsum().searchsorted(rng.random() * total, side="right"))
        c = z[min(i, len(z) - 1)]
        chosen.append(c)
        if len(chosen) < k:  # the last centre's distances would not be used
            d2 = np.minimum(d2, ((z - c) ** 2).sum(axis=1))
    return np.array(chosen, float).reshape(-1, 2)


def mixture_from_centres(
    z: np.ndarray,
    centres: np.ndarray,
    *,
    reg_covar: float,
    background_box: tuple[float, float, float, float] | None = None,
    background_weight: float = 0.0,
) -> Mixture:
    """A starting mixture: each plot goes to its nearest centre (a hard E-step), then one
    M-step. A centre with fewer than 3 plots (too few for a 2×2 covariance) gets the
    data's covariance divided by the number of centres (+ ``reg_covar``); a centre with no
    plot keeps its position with a tiny weight."""
    k = len(centres)
    d2 = ((z[:, None, :] - centres[None, :, :]) ** 2).sum(axis=2)
    lab = d2.argmin(axis=1)
    n_in = np.bincount(lab, minlength=k)
    sizes = n_in.tolist()
    counts = n_in.astype(float)
    reg = reg_covar * _EYE2
    # each centre's plots summed in plot order from 0.0: the additions of
    # z[lab == j].sum(axis=0), all centres in one pass; a mean is that sum / m
    sums = np.zeros((k, 2))
    np.add.at(sums, lab, z)
    means = centres.astype(float)  # a copy; a centre with no plot keeps its position
    np.divide(sums, counts[:, None], out=means, where=n_in[:, None] > 0)
    cov = np.empty((k, 2, 2))
    if min(sizes) < 3:  # some centre keeps the broad covariance
        data_cov = cov_biased(z) if len(z) > 1 else np.zeros((2, 2))
        cov[:] = data_cov / k + reg
    if max(sizes) >= 3:
        grouped = z.take(lab.argsort(kind="stable"), axis=0)  # centre by centre, in plot order
        stop = 0
        for j, m in enumerate(sizes):
            start, stop = stop, stop + m
            if m >= 3:
                d = grouped[start:stop] - means[j]  # z[lab == j] − μ_j
                cov[j] = d.T @ d / m + reg
    w = np.maximum(counts, 1e-3)
    w = (1.0 - background_weight) * w / w.sum()
    return Mixture(w, means, cov, float(background_weight), background_box)
