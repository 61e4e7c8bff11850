"""The dense adaptive K-means of mhtrack before issue 16 (all-pairs ``pdist`` and one
dense assignment matrix per radar), kept for tests only: the k-d tree version in
:mod:`mhtrack.initiation.kmeans` (:mod:`~mhtrack.initiation.neighbours`,
:mod:`~mhtrack.initiation.assignment`) must give the same clusters. O(n²) memory.

:func:`adaptive_fit` chains the steps as ``AdaptiveKMeansFusion.fit`` does (P2 §1.2 and
our covariance gate, threshold cap, merge and χ² split).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.spatial import cKDTree
from scipy.spatial.distance import pdist

from mhtrack.models.linalg2 import lmax2, mahalanobis2


# ---------------------------------------------------------------------- building blocks
def sorted_distances(z: np.ndarray) -> np.ndarray:
    """All pairwise distances ``‖z_i − z_j‖``, ``i < j``, sorted ascending (P2 §1.2 step 2)."""
    return np.sort(pdist(np.asarray(z, float).reshape(-1, 2)))


def dissimilarity_threshold(D: np.ndarray, k: int, n_sensors: int) -> float:
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


def _gated_assignment(
    z: np.ndarray,
    centres: np.ndarray,
    eps: float,
    R: np.ndarray | None = None,
    Rc: np.ndarray | None = None,
    gamma: float | None = None,
) -> np.ndarray:
    """One-to-one assignment of plots ``z`` to ``centres`` (P2 §1.2 step 4 with the
    one-plot-per-radar rule). Returns the centre index per plot, or ``−1`` for a plot
    that opens a new cluster.

    A pair is *allowed* when ``‖z − c‖ ≤ eps`` (P2) or, with plot covariances ``R``,
    centre covariances ``Rc`` and a gate ``gamma``, when ``(z − c)ᵀ (R + R̄c)⁻¹ (z − c) ≤ γ``
    (ours). Among allowed pairs the assignment minimises the total cost
    (``linear_sum_assignment``), leaving a plot unassigned costing ``stay``: without
    covariances cost ``‖z − c‖²`` and ``stay = eps²``; with them cost ``min(d², γ⁻)`` and
    ``stay = γ`` (``γ⁻`` just below ``γ``: a pair allowed by ``ε`` alone joins only when
    it takes no better pair's centre). A plot joins when an allowed centre is left for it.
    """
    m = len(z)
    out = np.full(m, -1, np.int64)
    if m == 0 or len(centres) == 0:
        return out
    stat = R is not None and Rc is not None and gamma is not None
    radius = eps
    if stat:
        radius = max(eps, float(np.sqrt(gamma * (lmax2(R).max() + lmax2(Rc).max()))))
    near = cKDTree(centres).query_ball_point(z, radius * (1 + 1e-12) + 1e-9)
    cols = np.unique(np.fromiter((j for h in near for j in h), np.int64))
    if cols.size == 0:
        return out
    delta = z[:, None, :] - centres[None, cols, :]
    d2 = (delta**2).sum(-1)
    allowed = d2 <= eps * eps
    if stat:
        dm, _ = mahalanobis2(delta, R[:, None] + Rc[None, cols])  # type: ignore[index]
        allowed |= dm <= gamma
        stay = float(gamma)  # type: ignore[arg-type]
        cost = np.minimum(dm, stay * (1 - 1e-9))  # allowed by ε only: just below "stay"
    else:
        cost = d2
        stay = eps * eps
    if not allowed.any():
        return out
    big = 2.0 * stay + 1.0
    full = np.full((m, len(cols) + m), big)
    full[:, : len(cols)] = np.where(allowed, cost, big)
    full[np.arange(m), len(cols) + np.arange(m)] = stay  # "open a new cluster"
    r, c = linear_sum_assignment(full)
    hit = (c < len(cols)) & (full[r, c] < big)
    out[r[hit]] = cols[c[hit]]
    return out


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
    D = sorted_distances(z)
    ns = len(order)

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
        a = _gated_assignment(z[idx], centres, eps(k), None if R is None else R[idx], Rc, gamma)
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


def enforce_one_plot_per_sensor(
    z: np.ndarray,
    sensor: np.ndarray,
    labels: np.ndarray,
    eps: float,
    R: np.ndarray | None = None,
    gamma: float | None = None,
) -> np.ndarray:
    """Labels in which no cluster holds two plots of one radar (P2 §1.2, §3.1).

    For each radar with offending clusters, its plots in those clusters are re-assigned by
    :func:`_gated_assignment` (one plot per centre, minimal total cost, within ``eps`` or
    the Mahalanobis gate ``gamma``) to the offending clusters and to the clusters holding
    no plot of that radar; a plot left over opens its own cluster (a split). Other labels
    are kept. Returns compact labels ``0..k−1``.
    """
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
            None if R is None else R[idx], None if Rc is None else Rc[targets], gamma,
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


def merge_compatible_clusters(
    z: np.ndarray,
    sensor: np.ndarray,
    labels: np.ndarray,
    eps: float,
    R: np.ndarray | None = None,
    gamma: float | None = None,
) -> np.ndarray:
    """Merge clusters that hold no plot of a common radar and look like one target (ours).

    P2's threshold ``ε(k)`` is the largest within-cluster distance only when targets are
    farther apart than their plots' spread; otherwise it is too small and a plot opens a
    cluster of its own beside its target's. Two *compatible* clusters (no common radar:
    their union still has one plot per radar) are merged when their centres pass

    * with the plots' covariances ``R`` and a gate ``gamma``: the Mahalanobis test
      ``d² = Δᵀ (R̄_a + R̄_b)⁻¹ Δ ≤ γ`` (``Δ`` the centre difference, ``R̄ = (1/n²) Σ R_i``
      the covariance of a cluster mean; ``d²`` is χ²₂ when both are one target);
    * otherwise: ``‖Δ‖ ≤ eps``.

    Each round merges the pairs that are each other's nearest (in that test's distance)
    compatible partner — reciprocal nearest neighbours, candidates from a k-d tree — and
    rounds repeat until none is left. Returns compact labels.
    """
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
        if maha:
            Rc = _cluster_cov(R, labels, k)  # type: ignore[arg-type]
            # d² ≤ γ needs ‖Δ‖² ≤ γ·λmax(R̄a + R̄b) ≤ γ·2·max λmax(R̄)
            radius = float(np.sqrt(gamma * 2.0 * lmax2(Rc).max()))  # type: ignore[operator]
        else:
            radius = eps
        pairs = cKDTree(centres).query_pairs(radius, output_type="ndarray")
        if len(pairs):
            pairs = pairs[~(has[pairs[:, 0]] & has[pairs[:, 1]]).any(axis=1)]
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


def adaptive_fit(z: np.ndarray, sensor: np.ndarray, R: np.ndarray | None,
                 merge_probability: float | None = 0.9999,
                 max_threshold: float | str | None = "auto",
                 consistency: float | None = None) -> tuple[np.ndarray, float]:
    """``AdaptiveKMeansFusion(merge_probability=p, max_threshold=m,
    consistency=q).fit(z, sensor, R)`` as it was: ``(labels_, threshold_)``."""
    gamma = None if merge_probability is None else float(-2.0 * np.log1p(-merge_probability))
    cap = max_threshold
    if cap == "auto":
        cap = None if R is None or gamma is None or not len(z) else float(
            np.sqrt(gamma * 2.0 * lmax2(R).max()))
    c0, _, eps = adaptive_initial_centres(z, sensor, R=R, gamma=gamma, max_threshold=cap)
    _, labels, _ = kmeans_lloyd(z, c0)
    if len(z):
        labels = enforce_one_plot_per_sensor(z, sensor, labels, eps, R, gamma)
        labels = merge_compatible_clusters(z, sensor, labels, eps, R, gamma)
    if consistency is not None and R is not None and len(z):
        labels = split_inconsistent(z, R, labels, consistency)
    return labels, float(eps)
