"""Fused plots: one plot per cluster of a scan's plots (P2 §1).

A fuser (:class:`~mhtrack.initiation.base.Fuser`) labels the plots of a scan, one cluster
per target; :func:`fused_scan` turns the labels into the fused scan. Fused plot: the
cluster centre ``z̄ = (1/n) Σ z_i`` with ``R̄ = (1/n²) Σ R_i`` (the covariance of a mean
of independent plots) — P2's choice — or, with ``weighting="information"``,
``P = (Σ R_i⁻¹)⁻¹``, ``z = P Σ R_i⁻¹ z_i``. A cluster of one plot is that plot, unchanged.
Origin of a fused plot (simulations): the target id with the most plots in the cluster
(ties: the lower id) unless clutter plots are strictly more numerous, then ``−1``
(clutter-dominated).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mhtrack.initiation.kmeans import _means
from mhtrack.records import CLUTTER, Scan

#: ``Scan.sensor`` value of a fused plot made of two or more radars' plots.
FUSED = -1
#: How a cluster's plots are combined (:func:`fuse_clusters`).
WEIGHTINGS = ("mean", "information")


def fuse_clusters(
    z: np.ndarray,
    labels: np.ndarray,
    R: np.ndarray | None = None,
    *,
    weighting: str = "mean",
) -> tuple[np.ndarray, np.ndarray | None]:
    """One fused plot per cluster ``0..k−1`` and its covariance.

    ``"mean"`` (P2): ``z̄ = (1/n) Σ z_i``, ``R̄ = (1/n²) Σ R_i``. ``"information"``:
    ``P = (Σ R_i⁻¹)⁻¹``, ``z = P Σ R_i⁻¹ z_i``. A one-plot cluster gives that plot and its
    ``R`` exactly in both cases. Without ``R`` the plots count as equally accurate, where
    both weightings give the plain centre (and no covariance).
    """
    if weighting not in WEIGHTINGS:
        raise ValueError(f"weighting must be one of {WEIGHTINGS}, got {weighting!r}")
    z = np.asarray(z, float).reshape(-1, 2)
    labels = np.asarray(labels, np.int64)
    k = int(labels.max()) + 1 if len(labels) else 0
    zc, n = _means(z, labels, k)
    if R is None:
        return zc, None
    R = np.asarray(R, float).reshape(-1, 2, 2)
    if weighting == "mean":
        Rs = np.zeros((k, 2, 2))
        np.add.at(Rs, labels, R)
        Rc = Rs / (n**2)[:, None, None]
    else:
        W = np.linalg.inv(R)
        Wsum = np.zeros((k, 2, 2))
        np.add.at(Wsum, labels, W)
        wz = np.zeros((k, 2))
        np.add.at(wz, labels, np.einsum("nij,nj->ni", W, z))
        Rc = np.linalg.inv(Wsum)
        zc = np.einsum("kij,kj->ki", Rc, wz)
    single = n == 1
    if single.any():  # exactly the plot: no rounding from inverting twice
        first = np.full(k, -1, np.int64)
        first[labels[::-1]] = np.arange(len(labels))[::-1]
        zc[single] = z[first[single]]
        Rc[single] = R[first[single]]
    return zc, 0.5 * (Rc + np.swapaxes(Rc, 1, 2))


def majority_origin(origin: np.ndarray, labels: np.ndarray, k: int) -> np.ndarray:
    """Origin of each fused plot: the target id with the most plots in the cluster (ties:
    the lower id), or ``−1`` when its clutter plots are strictly more numerous."""
    origin = np.asarray(origin, np.int64)
    out = np.full(k, CLUTTER, np.int64)
    if len(origin) == 0:
        return out
    n_clutter = np.bincount(labels[origin < 0], minlength=k)
    t = origin >= 0
    if t.any():
        pairs, counts = np.unique(
            np.column_stack((labels[t], origin[t])), axis=0, return_counts=True
        )
        # per label: max count, ties to the lower id → sort by (label, −count, id)
        o = np.lexsort((pairs[:, 1], -counts, pairs[:, 0]))
        pairs, counts = pairs[o], counts[o]
        first = np.r_[True, pairs[1:, 0] != pairs[:-1, 0]]
        lab, oid, cnt = pairs[first, 0], pairs[first, 1], counts[first]
        win = cnt >= n_clutter[lab]
        out[lab[win]] = oid[win]
    return out



@dataclass(frozen=True, slots=True)
class FusedScan:
    """Result of fusing one scan.

    ``scan`` holds one plot per cluster: ``z`` the fused position, ``R`` its covariance,
    ``sensor`` the radar id for a one-plot cluster or :data:`FUSED` (−1), ``rows`` the
    index of the fused plot in this scan (``0..k−1``; the input plots are mapped by
    ``labels``), ``origin`` the majority origin (:func:`majority_origin`) when known.
    ``labels[i]`` is the cluster of input plot ``i``; ``threshold`` the final ``ε``.
    """

    scan: Scan
    labels: np.ndarray
    threshold: float

    @property
    def n_clusters(self) -> int:
        return len(self.scan)



def fused_scan(scan: Scan, labels: np.ndarray, threshold: float, *,
               weighting: str = "mean") -> FusedScan:
    """The fused scan of ``scan`` whose plot ``i`` is in cluster ``labels[i]`` (``0..k−1``):
    :func:`fuse_clusters` positions and covariances, the radar id of one-plot clusters
    (else :data:`FUSED`), :func:`majority_origin` origins when known."""
    k = int(labels.max()) + 1 if len(labels) else 0
    z, R = fuse_clusters(scan.z, labels, scan.R, weighting=weighting)
    n = np.bincount(labels, minlength=k)
    sensor = np.full(k, FUSED, np.int64)
    single = n == 1
    sensor[labels[single[labels]]] = scan.sensor[single[labels]]
    origin = None if scan.origin is None else majority_origin(scan.origin, labels, k)
    fused = Scan(scan.index, scan.time, z, sensor, np.arange(k, dtype=np.int64), R, origin)
    return FusedScan(fused, labels, threshold)
