"""Multi-radar plot fusion (P2 §1): fused plots and the K-means fusion estimators.

At one scan the plots of ``N_s`` radars lie in tight blobs round the targets (P2 §1). The
clustering (:mod:`mhtrack.initiation.kmeans`) groups them, one cluster per target, and
each cluster becomes one *fused plot*; this module turns a scan into its fused scan.

Estimators (scikit-learn style ``fit``; ``fuse(scan)`` returns a :class:`FusedScan`):

* :class:`AdaptiveKMeansFusion` (P2 §1.2): adaptive initial centres, standard K-means,
  the one-plot-per-radar repair, then the merge of compatible clusters (ours); its
  parameters ``merge_probability`` and ``max_threshold`` set our covariance gate and
  threshold cap (see :mod:`mhtrack.initiation.kmeans`).
* :class:`KMeansFusion` (P2 §1.1): the ``k`` initial centres drawn at random among the
  plots (seeded), standard K-means, and the same one-plot-per-radar repair with ``ε(k)``
  of its own ``k``, but no merge.

Fused plot: the cluster centre ``z̄ = (1/n) Σ z_i`` with ``R̄ = (1/n²) Σ R_i`` (the
covariance of a mean of independent plots) — P2's choice — or, with
``weighting="information"``, ``P = (Σ R_i⁻¹)⁻¹``, ``z = P Σ R_i⁻¹ z_i``. A cluster of one
plot is that plot, unchanged. Origin of a fused plot (simulations): the target id with the
most plots in the cluster (ties: the lower id) unless clutter plots are strictly more
numerous, then ``−1`` (clutter-dominated).
"""

from __future__ import annotations

import abc
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mhtrack.initiation.kmeans import (
    _means,
    adaptive_initial_centres,
    dissimilarity_threshold,
    enforce_one_plot_per_sensor,
    kmeans_lloyd,
    merge_compatible_clusters,
    sorted_distances,
)
from mhtrack.models.linalg2 import lmax2
from mhtrack.records import CLUTTER, Scan

#: ``Scan.sensor`` value of a fused plot made of two or more radars' plots.
FUSED = -1
WEIGHTINGS = ("mean", "information")


# ---------------------------------------------------------------------- fused output
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


def split_inconsistent(
    z: np.ndarray, R: np.ndarray, labels: np.ndarray, probability: float
) -> np.ndarray:
    """Labels with every cluster made statistically consistent (ours).

    The plots of one point, independent with covariances ``R_i``, scatter round its
    information-weighted estimate ``ẑ`` (:func:`fuse_clusters`) so that
    ``T = Σ (z_i − ẑ)ᵀ R_i⁻¹ (z_i − ẑ)`` is χ² with ``2(n − 1)`` degrees of freedom
    (the residual sum of a weighted least-squares fit; Bar-Shalom, Willett & Tian 2011,
    multisensor measurement association). While ``T`` exceeds its ``probability``
    quantile, the plot with the largest term leaves the cluster as a cluster of its own.
    The clustering's Euclidean threshold ``ε`` can put two radars' plots of *different*
    points (e.g. two clutter plots 500 m apart with 50 m errors) into one cluster; fused,
    they would give a plot that is neither. Returns compact labels ``0..k'−1`` (the old
    clusters keep their order, split-off plots come after).
    """
    from scipy.stats import chi2

    z = np.asarray(z, float).reshape(-1, 2)
    R = np.asarray(R, float).reshape(-1, 2, 2)
    labels = np.asarray(labels, np.int64).copy()
    if len(labels) == 0:
        return labels
    k = int(labels.max()) + 1
    n = np.bincount(labels, minlength=k)
    W = np.linalg.inv(R)
    limit = chi2.ppf(probability, 2 * np.arange(int(n.max())))  # by n − 1
    nxt = k
    for c in np.flatnonzero(n >= 2):
        idx = np.flatnonzero(labels == c)
        while len(idx) >= 2:
            Wsum = W[idx].sum(0)
            zh = np.linalg.solve(Wsum, np.einsum("nij,nj->i", W[idx], z[idx]))
            d = z[idx] - zh
            term = np.einsum("ni,nij,nj->n", d, W[idx], d)
            if term.sum() <= limit[len(idx) - 1]:
                break
            worst = int(np.argmax(term))
            labels[idx[worst]] = nxt
            nxt += 1
            idx = np.delete(idx, worst)
    return labels


# ---------------------------------------------------------------------- estimators
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


class _Fusion(abc.ABC):
    """Shared ``fit`` output handling and :meth:`fuse` (scikit-learn style); subclasses
    implement :meth:`fit`."""

    weighting: str
    max_iter: int
    cluster_centers_: np.ndarray
    labels_: np.ndarray
    threshold_: float
    n_iter_: int

    def _check(self, z: object, sensor: object) -> tuple[np.ndarray, np.ndarray]:
        if self.weighting not in WEIGHTINGS:
            raise ValueError(f"weighting must be one of {WEIGHTINGS}, got {self.weighting!r}")
        if not (isinstance(self.max_iter, int) and self.max_iter >= 1):
            raise ValueError(f"max_iter must be an integer >= 1, got {self.max_iter!r}")
        za = np.asarray(z, float)
        if za.size == 0:
            za = za.reshape(0, 2)
        if za.ndim != 2 or za.shape[1] != 2:
            raise ValueError(f"plots must have shape (n, 2), got {za.shape}")
        if not np.isfinite(za).all():
            raise ValueError("plots contain non-finite coordinates")
        s = np.zeros(len(za), np.int64) if sensor is None else np.asarray(sensor).reshape(-1)
        if len(s) != len(za):
            raise ValueError(f"sensor has {len(s)} entries for {len(za)} plots")
        return za, s

    def _finish(self, z: np.ndarray, sensor: np.ndarray, labels: np.ndarray, eps: float,
                n_iter: int, adaptive: bool, R: np.ndarray | None = None,
                gamma: float | None = None) -> None:
        if len(z):
            labels = enforce_one_plot_per_sensor(z, sensor, labels, eps, R, gamma)
            if adaptive:
                labels = merge_compatible_clusters(z, sensor, labels, eps, R, gamma)
        k = int(labels.max()) + 1 if len(labels) else 0
        self.cluster_centers_, _ = _means(z, labels, k)
        self.labels_ = labels
        self.threshold_ = float(eps)
        self.n_iter_ = n_iter

    @property
    def n_clusters_(self) -> int:
        return len(self.cluster_centers_)

    @abc.abstractmethod
    def fit(self, z: np.ndarray, sensor: np.ndarray | None = None,
            R: np.ndarray | None = None) -> _Fusion:
        """Cluster plots ``z`` (n, 2) of radars ``sensor`` with covariances ``R``."""

    def fuse(self, scan: Scan) -> FusedScan:
        """Cluster ``scan``'s plots and return the fused scan (see :class:`FusedScan`)."""
        self.fit(scan.z, scan.sensor, scan.R)
        labels = self.labels_
        k = self.n_clusters_
        z, R = fuse_clusters(scan.z, labels, scan.R, weighting=self.weighting)
        n = np.bincount(labels, minlength=k)
        sensor = np.full(k, FUSED, np.int64)
        single = n == 1
        sensor[labels[single[labels]]] = scan.sensor[single[labels]]
        origin = None if scan.origin is None else majority_origin(scan.origin, labels, k)
        fused = Scan(scan.index, scan.time, z, sensor, np.arange(k, dtype=np.int64), R, origin)
        return FusedScan(fused, labels, self.threshold_)


class AdaptiveKMeansFusion(_Fusion):
    """P2 §1.2 adaptive K-means plot fusion (:mod:`mhtrack.initiation.kmeans`): the number
    of clusters and the initial centres from the sorted distances ``D``, then standard
    K-means, then the one-plot-per-radar repair, then the merge of compatible clusters.

    Parameters
    ----------
    weighting : ``"mean"`` (P2: the cluster centre) or ``"information"``.
    merge_probability : probability ``p`` of the covariance gate ``γ = −2 ln(1 − p)``
        (ours, 0.9999); ``None``: Euclidean ``ε`` only.
    max_threshold : cap (m) on ``ε``; ``"auto"`` (ours): ``√(γ · 2 · max λmax(R))`` when
        the plots carry ``R``; ``None``: P2's ``ε`` uncapped.
    max_iter : K-means iterations at most.
    consistency : probability ``p`` of a final χ² test of each cluster
        (:func:`split_inconsistent`, ours), which splits off the plots that cannot be of one
        point; needs ``R``. Default ``None`` (off: P2's clusters).

    Attributes (after :meth:`fit`)
    ----------
    initial_centers_, cluster_centers_ : (k₀, 2) adaptive initial and (k, 2) final centres.
    labels_ : cluster of each plot. threshold_ : final ``ε``. n_iter_ : K-means iterations.
    n_clusters_ : ``k``. threshold_cap_ : the cap applied to ``ε`` (or None).
    """

    def __init__(self, *, weighting: str = "mean", merge_probability: float | None = 0.9999,
                 max_threshold: float | str | None = "auto", max_iter: int = 300,
                 consistency: float | None = None) -> None:
        self.weighting = weighting
        self.merge_probability = merge_probability
        self.max_threshold = max_threshold
        self.max_iter = max_iter
        self.consistency = consistency

    def fit(self, z: np.ndarray, sensor: np.ndarray | None = None,
            R: np.ndarray | None = None) -> AdaptiveKMeansFusion:
        """Cluster plots ``z`` (n, 2) of radars ``sensor`` (n,) (all one radar if None)
        with covariances ``R`` (n, 2, 2) (optional; used by the merge test)."""
        za, s = self._check(z, sensor)
        p = self.merge_probability
        if p is not None and not 0.0 < p < 1.0:
            raise ValueError(f"merge_probability must be in (0, 1) or None, got {p!r}")
        gamma = None if p is None else float(-2.0 * np.log1p(-p))  # χ²₂ quantile
        Ra = None if R is None else np.asarray(R, float).reshape(len(za), 2, 2)
        cap = self.max_threshold
        if cap == "auto":
            # two plots of one target differ by N(0, R_i + R_j): farther than
            # sqrt(γ·2·max λmax(R)) fails the gate whatever their direction
            cap = None if Ra is None or gamma is None or not len(za) else float(
                np.sqrt(gamma * 2.0 * lmax2(Ra).max()))
        elif cap is not None and not (isinstance(cap, int | float) and cap > 0):
            raise ValueError(f"max_threshold must be > 0, 'auto' or None, got {cap!r}")
        self.threshold_cap_ = cap
        c0, _, eps = adaptive_initial_centres(za, s, R=Ra, gamma=gamma, max_threshold=cap)
        self.initial_centers_ = c0
        q = self.consistency
        if q is not None and not (isinstance(q, float) and 0.0 < q < 1.0):
            raise ValueError(f"consistency must be in (0, 1) or None, got {q!r}")
        _, labels, it = kmeans_lloyd(za, c0, max_iter=self.max_iter)
        self._finish(za, s, labels, eps, it, adaptive=True, R=Ra, gamma=gamma)
        if q is not None and Ra is not None and len(za):
            self.labels_ = split_inconsistent(za, Ra, self.labels_, q)
            self.cluster_centers_, _ = _means(za, self.labels_, int(self.labels_.max()) + 1)
        return self


class KMeansFusion(_Fusion):
    """Standard K-means plot fusion (P2 §1.1): ``n_clusters`` initial centres drawn at
    random among the plots (without replacement, ``numpy.random.default_rng(random_state)``),
    then Lloyd iterations, then the one-plot-per-radar repair with the threshold
    ``ε(k) = D(k·C(N_s, 2))`` of the adaptive method (:mod:`mhtrack.initiation.kmeans`).

    ``n_clusters`` larger than the number of plots is reduced to it. Attributes as
    :class:`AdaptiveKMeansFusion` (``initial_centers_`` are the drawn plots).
    """

    def __init__(self, n_clusters: int, *, random_state: int | Sequence[int] | None = None,
                 weighting: str = "mean", max_iter: int = 300) -> None:
        self.n_clusters = n_clusters
        self.random_state = random_state
        self.weighting = weighting
        self.max_iter = max_iter

    def fit(self, z: np.ndarray, sensor: np.ndarray | None = None,
            R: np.ndarray | None = None) -> KMeansFusion:
        """Cluster plots ``z`` (n, 2) of radars ``sensor`` (n,) (all one radar if None);
        ``R`` is accepted for a common interface and not used."""
        za, s = self._check(z, sensor)
        if not (isinstance(self.n_clusters, int | np.integer) and self.n_clusters >= 1):
            raise ValueError(f"n_clusters must be an integer >= 1, got {self.n_clusters!r}")
        rng = np.random.default_rng(self.random_state)
        k = min(int(self.n_clusters), len(za))
        c0 = za[rng.choice(len(za), size=k, replace=False)] if k else np.zeros((0, 2))
        self.initial_centers_ = c0
        c, labels, it = kmeans_lloyd(za, c0, max_iter=self.max_iter)
        eps = dissimilarity_threshold(sorted_distances(za), len(c), len(np.unique(s)))
        self._finish(za, s, labels, eps, it, adaptive=False)
        return self
