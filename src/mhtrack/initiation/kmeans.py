"""Multi-radar plot clustering: standard and adaptive K-means (P2 §1).

At one scan the plots of ``N_s`` radars lie in tight blobs round the targets (P2 §1). A
clustering groups them, one cluster per target; this module holds the clustering building
blocks, and :mod:`mhtrack.initiation.fusion` the estimators that chain them and turn each
cluster into one *fused plot* (:class:`~mhtrack.initiation.fusion.AdaptiveKMeansFusion`,
:class:`~mhtrack.initiation.fusion.KMeansFusion`).

Standard K-means (P2 §1.1; Lloyd, :func:`kmeans_lloyd`): given ``k`` initial centres,
repeat — assign every plot to its nearest centre (Euclidean ``d(x, c) = ‖x − c‖``), move
every centre to the mean ``c_j = (1/n_j) Σ_{x∈C_j} x`` of its plots — until the labels
stop changing.

Adaptive K-means (P2 §1.2, steps 1–6; :func:`adaptive_initial_centres`), as implemented
here:

1. ``D`` = all ``C(n, 2)`` pairwise plot distances sorted ascending; only the part that
   ``ε(k)`` can read is computed (:class:`~mhtrack.initiation.neighbours.SortedDistances`).
2. Dissimilarity threshold for ``k`` clusters: ``ε(k) = D[k·C(N_s, 2)]`` read **1-based**
   as P2 prints it (``D(1)`` the smallest), i.e. ``D[k·C(N_s,2) − 1]`` 0-based, clipped to
   ``[0, len(D) − 1]``. Why: ``k`` clusters of ``N_s`` plots hold ``k·C(N_s, 2)``
   within-cluster pairs; when the clusters are apart these are the ``k·C(N_s, 2)``
   smallest distances, so the ``(k·C(N_s,2))``-th smallest is the largest within-cluster
   distance — P2 Fig. 1's threshold ``d₁``. ``N_s`` = number of distinct radars in the scan.
3. Start with ``k = 1`` centre; 4. a plot whose distance to every (allowed) centre exceeds
   ``ε(k)`` opens a new cluster (``k += 1``, ``ε`` updated), otherwise it joins the
   nearest centre; centres are updated to their members' means; 5. until every plot is
   placed; 6. refine with standard K-means from these centres.

The order in which plots are visited is ours (P2 picks the first centre at random and
leaves the order open): radar by radar, the radar with the most plots first (ties: lower
id). Because a cluster holds at most one plot per radar (P2 §1.2, §3.1), every plot of
the first radar opens its own cluster, so *which* of its plots is the first centre does
not change the result — the method is deterministic. The plots of each later radar are
placed together: each joins an *allowed* centre that holds no plot of its radar, one plot
per centre, by an optimal assignment (``linear_sum_assignment``); plots left over open
new clusters, ``k`` grows and ``ε(k)`` is re-read before the next radar. When no two
plots of the radar compete for a centre this is exactly P2's "join the nearest".

Our additions (each one documented, overridable parameter of
:class:`~mhtrack.initiation.fusion.AdaptiveKMeansFusion`), needed because P2's ``ε(k)``
equals the largest within-cluster distance only when the targets are farther apart than
their plots' spread — on P2's own geometry (targets 100–300 m apart, plots σ ≈ 50 m
cross-range) it often is too small, and in clutter it is far too large:

* **Covariance gate** (``merge_probability = 0.9999``, when the plots carry ``R``): a pair
  plot–centre is also allowed when ``d² = (z − c)ᵀ (R + R̄_c)⁻¹ (z − c) ≤ γ``, ``γ`` the
  χ²₂ quantile (``−2 ln(1 − p)`` = 18.4), ``R̄_c = (1/n²) Σ R_i`` the covariance of the
  centre; the assignment then minimises ``Σ min(d², γ)`` (plain ``Σ ‖z − c‖²`` without
  ``R``), leaving a plot alone costing ``γ`` (``ε²``).
* **Threshold cap** (``max_threshold = "auto"``): ``ε ≤ √(γ · 2 · max_i λmax(R_i))``, the
  largest distance at which two plots of one target can still pass the gate; keeps clutter
  (which inflates ``D``'s upper part) from joining target clusters.
* **Merge** (after the refinement and the rule below): two clusters holding no plot of a
  common radar are merged when their centres pass the gate
  ``Δᵀ (R̄_a + R̄_b)⁻¹ Δ ≤ γ`` (``‖Δ‖ ≤ ε`` without ``R``), reciprocal nearest pairs
  first, until none is left (:func:`merge_compatible_clusters`).

With ``merge_probability=None, max_threshold=None`` (or plots without ``R``; then the
merge uses ``ε``) only P2's Euclidean threshold is used. In
:class:`~mhtrack.initiation.fusion.AdaptiveKMeansFusion` the repair below, the merge and
the gate are the named options ``enforce_one_per_radar``, ``merge`` and ``gate`` (all off
in ``AdaptiveKMeansFusion.paper()``, P2's steps only).

One plot per radar (P2 §1.2, §3.1). The K-means refinement ignores radars and may put two
plots of one radar in a cluster. Such clusters are repaired, radar by radar: the plots of
that radar in offending clusters are re-assigned optimally (same assignment as above) to
those clusters and to clusters holding no plot of that radar; a plot with no allowed
centre left opens its own cluster (a split). One pass suffices; the labels that did not
break the rule are kept (:func:`enforce_one_plot_per_sensor`).

Memory is O(n · neighbours), never O(n²): the distances and the assignments come from k-d
trees (:mod:`mhtrack.initiation.neighbours`, :mod:`mhtrack.initiation.assignment`; the same
numbers as the dense formulas on normal scans, caps counted in a burst).
The fused output and the estimators live in :mod:`mhtrack.initiation.fusion`, which
imports this module (never the other way round). 2×2 algebra: :mod:`mhtrack.models.linalg2`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

import numpy as np

from mhtrack.initiation.assignment import gated_assignment as _gated_assignment
from mhtrack.initiation.neighbours import SortedDistances, close_pairs
from mhtrack.models.linalg2 import lmax2, mahalanobis2


# ---------------------------------------------------------------------- building blocks
def sorted_distances(z: np.ndarray) -> np.ndarray:
    """All pairwise distances ``‖z_i − z_j‖``, ``i < j``, sorted ascending (P2 §1.2 step 2).
    O(n²) memory: for many plots use :class:`~mhtrack.initiation.neighbours.SortedDistances`."""
    from scipy.spatial.distance import pdist
    return np.sort(pdist(np.asarray(z, float).reshape(-1, 2)))


def dissimilarity_threshold(D: np.ndarray | SortedDistances, k: int, n_sensors: int) -> float:
    """``ε(k) = D(k·C(N_s, 2))`` of P2 §1.2 step 3, ``D`` sorted ascending and indexed
    1-based as printed (0-based index ``k·C(N_s,2) − 1``), clipped to ``D``'s range.

    ``0`` when there is one radar (``C(1, 2) = 0``: nothing to fuse) or at most one plot.
    """
    pairs = n_sensors * (n_sensors - 1) // 2
    if pairs == 0 or len(D) == 0:
        return 0.0
    return float(D[int(np.clip(k * pairs - 1, 0, len(D) - 1))])


def _means(z: np.ndarray, labels: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Centre ``(1/n_j) Σ x`` of each label ``0..k−1`` and the counts ``n_j``."""
    n = np.bincount(labels, minlength=k)
    c = np.column_stack(
        (np.bincount(labels, z[:, 0], minlength=k), np.bincount(labels, z[:, 1], minlength=k))
    )
    with np.errstate(invalid="ignore", divide="ignore"):
        return c / n[:, None], n


def _compact(labels: np.ndarray) -> np.ndarray:
    """Relabel to ``0..k−1`` keeping the order of the old labels (drops unused ones)."""
    _, inv = np.unique(labels, return_inverse=True)
    return inv.astype(np.int64)


def _cluster_cov(R: np.ndarray, labels: np.ndarray, k: int) -> np.ndarray:
    """Covariance of each cluster's mean, ``R̄ = (1/n²) Σ R_i`` (independent plots)."""
    n = np.bincount(labels, minlength=k)
    Rc = np.zeros((k, 2, 2))
    np.add.at(Rc, labels, R)
    with np.errstate(invalid="ignore", divide="ignore"):
        return Rc / (n**2)[:, None, None]


def _no_common_radar(has: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """Pairs of clusters (rows of ``has``: radars present) with no radar in common."""
    return ~(has[pairs[:, 0]] & has[pairs[:, 1]]).any(axis=1)


def _sensor_order(sensor: np.ndarray) -> np.ndarray:
    """Radar ids, the one with the most plots first (ties: lower id)."""
    ids, counts = np.unique(sensor, return_counts=True)
    return ids[np.lexsort((ids, -counts))]


def adaptive_initial_centres(
    z: np.ndarray,
    sensor: np.ndarray,
    *,
    R: np.ndarray | None = None,
    gamma: float | None = None,
    max_threshold: float | None = None,
    caps: dict[str, int] | None = None,
) -> tuple[np.ndarray, np.ndarray, float]:
    """P2 §1.2 steps 1–6: the number of clusters and their initial centres.

    Radar by radar (most plots first), each plot joins an allowed centre or opens a
    cluster (:func:`_gated_assignment`: ``‖z − c‖ ≤ ε(k)``, or the Mahalanobis gate
    ``γ`` when ``R`` and ``gamma`` are given); ``ε(k) = D(k·C(N_s, 2))`` is re-read from
    the sorted distances as ``k`` grows (capped at ``max_threshold`` when given); centres
    are the means of their plots. Returns ``(centres (k, 2), labels (n,), ε(k))``.
    """
    z = np.asarray(z, float).reshape(-1, 2)
    sensor = np.asarray(sensor).reshape(-1)
    n = len(z)
    labels = np.full(n, -1, np.int64)
    if n == 0:
        return np.zeros((0, 2)), labels, 0.0
    order = _sensor_order(sensor)
    ns = len(order)
    # k ≤ n clusters: ε(k) reads D at most at index n·C(N_s, 2) − 1
    D = SortedDistances(z, n * (ns * (ns - 1) // 2), max_threshold)

    def eps(k: int) -> float:
        e = dissimilarity_threshold(D, k, ns)
        return e if max_threshold is None else min(e, max_threshold)

    first = np.flatnonzero(sensor == order[0])
    labels[first] = np.arange(len(first))
    k = len(first)
    centres = z[first].copy()
    Rc = None if R is None else R[first].copy()
    for s in order[1:]:
        idx = np.flatnonzero(sensor == s)
        a = _gated_assignment(z[idx], centres, eps(k), None if R is None else R[idx], Rc, gamma,
                              caps)
        new = a < 0
        a[new] = k + np.arange(int(new.sum()))
        labels[idx] = a
        k += int(new.sum())
        placed = labels >= 0
        centres, _ = _means(z[placed], labels[placed], k)
        if R is not None:
            Rc = _cluster_cov(R[placed], labels[placed], k)
    return centres, labels, eps(k)


def kmeans_lloyd(
    z: np.ndarray, centres: np.ndarray, *, max_iter: int = 300
) -> tuple[np.ndarray, np.ndarray, int]:
    """Standard K-means (P2 §1.1; Lloyd's algorithm) from the given initial ``centres``.

    Repeat: ``label_i = argmin_j ‖z_i − c_j‖``, ``c_j = mean{z_i : label_i = j}``, until
    the labels do not change (or ``max_iter`` assignments). A centre left with no plot is
    dropped (scikit-learn moves it to a far plot instead; with centres drawn from the plots
    this is rare). Returns ``(centres, labels, n_iter)``; centres are the means of the
    final labels. Equals ``sklearn.cluster.KMeans(init=centres, n_init=1, tol=0)``
    when no cluster empties.
    """
    from scipy.spatial import cKDTree
    z = np.asarray(z, float).reshape(-1, 2)
    c = np.asarray(centres, float).reshape(-1, 2).copy()
    if len(z) == 0 or len(c) == 0:
        return c[:0], np.zeros(len(z), np.int64), 0
    prev: np.ndarray | None = None
    n_iter = 0
    while n_iter < max_iter:
        n_iter += 1
        labels = cKDTree(c).query(z)[1].astype(np.int64)
        if prev is not None and np.array_equal(labels, prev):
            break
        c, cnt = _means(z, labels, len(c))
        if (cnt == 0).any():
            labels = _compact(labels)
            c, _ = _means(z, labels, int(labels.max()) + 1)
        prev = labels
    labels = _compact(labels)
    c, _ = _means(z, labels, int(labels.max()) + 1)
    return c, labels, n_iter


@dataclass(frozen=True)
class Gate:
    """When a plot and a centre, or two centres, may be one target's (module docstring):
    within ``eps`` metres (P2's threshold ``ε(k)``) or, with the plots' covariances ``R``
    (n, 2, 2) and a χ²₂ gate ``gamma``, when the Mahalanobis test ``d² ≤ gamma`` passes."""

    eps: float
    R: np.ndarray | None = None
    gamma: float | None = None


def enforce_one_plot_per_sensor(z: np.ndarray, sensor: np.ndarray, labels: np.ndarray,
                                gate: Gate, caps: dict[str, int] | None = None) -> np.ndarray:
    """Labels in which no cluster holds two plots of one radar (P2 §1.2, §3.1).

    For each radar with offending clusters, its plots in those clusters are re-assigned by
    :func:`_gated_assignment` (one plot per centre, minimal total cost, within the
    ``gate``) to the offending clusters and to the clusters holding no plot of that radar;
    a plot left over opens its own cluster (a split). Other labels are kept. Returns
    compact labels ``0..k−1``.
    """
    eps, R, gamma = gate.eps, gate.R, gate.gamma
    z = np.asarray(z, float).reshape(-1, 2)
    sensor = np.asarray(sensor).reshape(-1)
    labels = np.asarray(labels, np.int64).copy()
    if len(z) == 0:
        return labels
    labels = _compact(labels)
    k = int(labels.max()) + 1
    centres, _ = _means(z, labels, k)
    Rc = None if R is None else _cluster_cov(R, labels, k)
    for s in np.unique(sensor):
        mine = sensor == s
        per = np.bincount(labels[mine], minlength=k)
        bad = per > 1
        if not bad.any():
            continue
        idx = np.flatnonzero(mine & bad[labels])
        targets = np.flatnonzero(bad | (per == 0))
        a = _gated_assignment(
            z[idx], centres[targets], eps,
            None if R is None else R[idx], None if Rc is None else Rc[targets], gamma, caps,
        )
        new = a < 0
        lab = np.where(new, -1, targets[np.maximum(a, 0)])
        lab[new] = k + np.arange(int(new.sum()))
        k += int(new.sum())
        labels[idx] = lab
        centres = np.vstack((centres, z[idx[new]]))
        if Rc is not None and R is not None:
            Rc = np.concatenate((Rc, R[idx[new]]))
    return _compact(labels)


def merge_compatible_clusters(z: np.ndarray, sensor: np.ndarray, labels: np.ndarray,
                              gate: Gate) -> np.ndarray:
    """Merge clusters that hold no plot of a common radar and look like one target (ours).

    P2's threshold ``ε(k)`` is the largest within-cluster distance only when targets are
    farther apart than their plots' spread; otherwise it is too small and a plot opens a
    cluster of its own beside its target's. Two *compatible* clusters (no common radar:
    their union still has one plot per radar) are merged when their centres pass

    * with the plots' covariances ``R`` and a gate ``gamma`` (``gate``): the Mahalanobis test
      ``d² = Δᵀ (R̄_a + R̄_b)⁻¹ Δ ≤ γ`` (``Δ`` the centre difference, ``R̄ = (1/n²) Σ R_i``
      the covariance of a cluster mean; ``d²`` is χ²₂ when both are one target);
    * otherwise: ``‖Δ‖ ≤ eps``.

    Each round merges the pairs that are each other's nearest (in that test's distance)
    compatible partner — reciprocal nearest neighbours, candidates from a k-d tree — and
    rounds repeat until none is left. In a burst the candidates are searched chunk by chunk
    (:func:`~mhtrack.initiation.neighbours.close_pairs`). Returns compact labels.
    """
    eps, R, gamma = gate.eps, gate.R, gate.gamma
    z = np.asarray(z, float).reshape(-1, 2)
    labels = np.asarray(labels, np.int64).copy()
    maha = R is not None and gamma is not None
    if len(labels) == 0 or (not maha and eps <= 0):
        return labels
    ids, s_idx = np.unique(np.asarray(sensor).reshape(-1), return_inverse=True)
    if maha:
        R = np.asarray(R, float).reshape(-1, 2, 2)
    while True:
        labels = _compact(labels)
        k = int(labels.max()) + 1
        centres, _ = _means(z, labels, k)
        has = np.zeros((k, len(ids)), bool)
        has[labels, s_idx] = True
        own = None
        if maha:
            Rc = _cluster_cov(R, labels, k)  # type: ignore[arg-type]
            lam = lmax2(Rc)  # d² ≤ γ needs ‖Δ‖² ≤ γ·λmax(R̄a + R̄b) ≤ γ·(λmax R̄a + max λmax R̄)
            radius = float(np.sqrt(gamma * 2.0 * lam.max()))  # type: ignore[operator]
            own = np.sqrt(gamma * (lam + lam.max())) * (1 + 1e-12)  # type: ignore[operator]
        else:
            radius = eps
        pairs = close_pairs(centres, radius, own, partial(_no_common_radar, has))
        if len(pairs):
            delta = centres[pairs[:, 0]] - centres[pairs[:, 1]]
            if maha:
                d, _ = mahalanobis2(delta, Rc[pairs[:, 0]] + Rc[pairs[:, 1]])
                keep = d <= gamma
            else:
                d = np.hypot(delta[:, 0], delta[:, 1])
                keep = d <= eps
            pairs, d = pairs[keep], d[keep]
        if len(pairs) == 0:
            return labels
        a = np.concatenate((pairs[:, 0], pairs[:, 1]))
        b = np.concatenate((pairs[:, 1], pairs[:, 0]))
        o = np.lexsort((b, np.tile(d, 2), a))  # per cluster a: nearest partner first
        a, b = a[o], b[o]
        first = np.r_[True, a[1:] != a[:-1]]
        nn = np.full(k, -1, np.int64)
        nn[a[first]] = b[first]
        ar = np.arange(k)
        mutual = (nn >= 0) & (nn[np.maximum(nn, 0)] == ar) & (ar < nn)
        if not mutual.any():  # exact ties only: merge the closest pair
            i, j = sorted(pairs[int(np.argmin(d))].tolist())
            mutual[i], nn[i] = True, j
        into = ar.copy()
        into[nn[mutual]] = ar[mutual]
        labels = into[labels]
