"""Multi-radar plot fusion (P2 §1): the K-means fusers.

At one scan the plots of ``N_s`` radars lie in tight blobs round the targets (P2 §1). The
clustering (:mod:`mhtrack.initiation.kmeans`) groups them, one cluster per target, and
each cluster becomes one *fused plot* (:mod:`mhtrack.initiation.fused`).

Fusers (:class:`~mhtrack.initiation.base.Fuser`: scikit-learn style ``fit``;
``fuse(scan)`` returns a :class:`~mhtrack.initiation.fused.FusedScan`):

* :class:`AdaptiveKMeansFusion` (P2 §1.2): adaptive initial centres, standard K-means,
  the one-plot-per-radar repair, then the merge of compatible clusters (ours); its
  parameters ``merge_probability`` and ``max_threshold`` set our covariance gate and
  threshold cap (see :mod:`mhtrack.initiation.kmeans`); ``enforce_one_per_radar``,
  ``merge`` and ``gate`` switch our three steps (``AdaptiveKMeansFusion.paper()``: off).
* :class:`KMeansFusion` (P2 §1.1): the ``k`` initial centres drawn at random among the
  plots (seeded), standard K-means, and the same one-plot-per-radar repair with ``ε(k)``
  of its own ``k``, but no merge.

Cluster consistency (ours, optional): :func:`split_inconsistent`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from mhtrack.initiation.base import Fuser
from mhtrack.initiation.fused import WEIGHTINGS
from mhtrack.initiation.kmeans import (
    Gate,
    _means,
    adaptive_initial_centres,
    dissimilarity_threshold,
    enforce_one_plot_per_sensor,
    kmeans_lloyd,
    merge_compatible_clusters,
)
from mhtrack.initiation.neighbours import SortedDistances
from mhtrack.models.linalg2 import lmax2


def split_inconsistent(
    z: np.ndarray, R: np.ndarray, labels: np.ndarray, probability: float
) -> np.ndarray:
    """Labels with every cluster made statistically consistent (ours).

    The plots of one point, independent with covariances ``R_i``, scatter round its
    information-weighted estimate ``ẑ`` (:func:`~mhtrack.initiation.fused.fuse_clusters`) so that
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
    by_label = np.argsort(labels, kind="stable")  # each cluster's plots, ascending
    start = np.cumsum(n) - n
    # first test of all clusters of one size at once (same arithmetic as the loop below)
    consistent = np.zeros(k, bool)
    for size in np.unique(n[n >= 2]).tolist():
        cs = np.flatnonzero(n == size)
        idx = by_label[start[cs][:, None] + np.arange(size)]
        Wi, zi = W[idx], z[idx]
        zh = np.linalg.solve(Wi.sum(1), np.einsum("cnij,cnj->ci", Wi, zi)[..., None])[..., 0]
        d = zi - zh[:, None]
        term = np.einsum("cni,cnij,cnj->cn", d, Wi, d)
        consistent[cs] = term.sum(1) <= limit[size - 1]
    for c in np.flatnonzero((n >= 2) & ~consistent):
        idx = by_label[start[c]:start[c] + n[c]]
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


class _KMeansFuser(Fuser):
    """What the two K-means fusers share: the parameter and plot checks, and the end of
    :meth:`fit` (one-plot-per-radar repair, optional merge, the fitted attributes)."""

    max_iter: int
    cluster_centers_: np.ndarray
    n_iter_: int
    #: Caps of the sparse assignment that acted in the last :meth:`fit` (a burst;
    #: :func:`~mhtrack.initiation.assignment.sparse_gated_assignment`): name → count.
    caps_: dict[str, int]

    def _check(self, z: object, sensor: object) -> tuple[np.ndarray, np.ndarray]:
        if self.weighting not in WEIGHTINGS:
            raise ValueError(f"weighting must be one of {WEIGHTINGS}, got {self.weighting!r}")
        if not (isinstance(self.max_iter, int) and self.max_iter >= 1):
            raise ValueError(f"max_iter must be an integer >= 1, got {self.max_iter!r}")
        return self.check_plots(z, sensor)

    def _finish(self, z: np.ndarray, sensor: np.ndarray, labels: np.ndarray, eps: float,
                n_iter: int, adaptive: bool, R: np.ndarray | None = None,
                gamma: float | None = None, enforce: bool = True) -> None:
        if len(z):
            gate = Gate(eps, R, gamma)
            if enforce:
                labels = enforce_one_plot_per_sensor(z, sensor, labels, gate, self.caps_)
            if adaptive:
                labels = merge_compatible_clusters(z, sensor, labels, gate)
        k = int(labels.max()) + 1 if len(labels) else 0
        self.cluster_centers_, _ = _means(z, labels, k)
        self.labels_ = labels
        self.threshold_ = float(eps)
        self.n_iter_ = n_iter

    @property
    def n_clusters_(self) -> int:
        return len(self.cluster_centers_)


class AdaptiveKMeansFusion(_KMeansFuser):
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
    enforce_one_per_radar : after the K-means refinement, repair clusters holding two plots
        of one radar by reassignment (ours, on; P2 states the rule but only for the
        initial centres — :func:`~mhtrack.initiation.kmeans.enforce_one_plot_per_sensor`).
    merge : merge compatible clusters after the refinement (ours, on;
        :func:`~mhtrack.initiation.kmeans.merge_compatible_clusters`).
    gate : use the covariance gate and threshold cap (``merge_probability``,
        ``max_threshold``; ours, on); ``False``: P2's Euclidean ``ε(k)`` only.

    ``AdaptiveKMeansFusion.paper()`` is P2 §1.2 as P2 states it: the three options off.

    Attributes (after :meth:`fit`)
    ----------
    initial_centers_, cluster_centers_ : (k₀, 2) adaptive initial and (k, 2) final centres.
    labels_ : cluster of each plot. threshold_ : final ``ε``. n_iter_ : K-means iterations.
    n_clusters_ : ``k``. threshold_cap_ : the cap applied to ``ε`` (or None).
    """

    def __init__(self, *, weighting: str = "mean", merge_probability: float | None = 0.9999,
                 max_threshold: float | str | None = "auto", max_iter: int = 300,
                 consistency: float | None = None, enforce_one_per_radar: bool = True,
                 merge: bool = True, gate: bool = True) -> None:
        self.enforce_one_per_radar = enforce_one_per_radar
        self.merge = merge
        self.gate = gate
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
        if not self.gate:
            p = None
        gamma = None if p is None else float(-2.0 * np.log1p(-p))  # χ²₂ quantile
        Ra = None if R is None else np.asarray(R, float).reshape(len(za), 2, 2)
        cap = self.max_threshold if self.gate else None
        if cap == "auto":
            # two plots of one target differ by N(0, R_i + R_j): farther than
            # sqrt(γ·2·max λmax(R)) fails the gate whatever their direction
            cap = None if Ra is None or gamma is None or not len(za) else float(
                np.sqrt(gamma * 2.0 * lmax2(Ra).max()))
        elif cap is not None and not (isinstance(cap, int | float) and cap > 0):
            raise ValueError(f"max_threshold must be > 0, 'auto' or None, got {cap!r}")
        self.threshold_cap_ = cap
        self.caps_ = {}
        c0, _, eps = adaptive_initial_centres(za, s, R=Ra, gamma=gamma, max_threshold=cap,
                                              caps=self.caps_)
        self.initial_centers_ = c0
        q = self.consistency
        if q is not None and not (isinstance(q, float) and 0.0 < q < 1.0):
            raise ValueError(f"consistency must be in (0, 1) or None, got {q!r}")
        _, labels, it = kmeans_lloyd(za, c0, max_iter=self.max_iter)
        self._finish(za, s, labels, eps, it, adaptive=self.merge, R=Ra, gamma=gamma,
                     enforce=self.enforce_one_per_radar)
        if q is not None and Ra is not None and len(za):
            self.labels_ = split_inconsistent(za, Ra, self.labels_, q)
            self.cluster_centers_, _ = _means(za, self.labels_, int(self.labels_.max()) + 1)
        return self

    @classmethod
    def paper(cls, **params: object) -> AdaptiveKMeansFusion:
        """P2 §1.2 as P2 states it: no repair, no merge, no gate (``params`` as
        :meth:`__init__`)."""
        kw: dict[str, object] = {"enforce_one_per_radar": False, "merge": False,
                                 "gate": False, **params}
        return cls(**kw)  # type: ignore[arg-type]


#: Named settings of :class:`AdaptiveKMeansFusion`: ``"paper"`` (P2 §1.2 only) and
#: ``"best"`` (ours: repair, merge, gate on — the default).
FUSION_SETTINGS: dict[str, dict[str, bool]] = {
    "paper": {"enforce_one_per_radar": False, "merge": False, "gate": False},
    "best": {"enforce_one_per_radar": True, "merge": True, "gate": True},
}


class KMeansFusion(_KMeansFuser):
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
        self.caps_ = {}
        rng = np.random.default_rng(self.random_state)
        k = min(int(self.n_clusters), len(za))
        c0 = za[rng.choice(len(za), size=k, replace=False)] if k else np.zeros((0, 2))
        self.initial_centers_ = c0
        c, labels, it = kmeans_lloyd(za, c0, max_iter=self.max_iter)
        ns = len(np.unique(s))
        D = SortedDistances(za, len(c) * (ns * (ns - 1) // 2))  # read at k·C(N_s,2) − 1
        eps = dissimilarity_threshold(D, len(c), ns)
        self._finish(za, s, labels, eps, it, adaptive=False)
        return self
