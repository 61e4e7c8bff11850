"""The gated one-to-one assignment of a radar's plots to cluster centres (P2 §1.2 step
4 with the one-plot-per-radar rule; :mod:`mhtrack.initiation.kmeans`), without an
all-pairs matrix in bursts.

:func:`gated_assignment` solves small problems on one dense matrix, as always
(``linear_sum_assignment``; :func:`assign_dense`). Beyond :data:`DENSE_ENTRIES` entries
(a clutter burst: 50 000 plots against 50 000 centres would be a 37 GiB matrix),
:func:`sparse_gated_assignment` forms only the *allowed* plot–centre pairs
(:func:`allowed_pairs`, k-d trees, chunk by chunk) and splits the problem into the
connected components of those pairs, each solved exactly on its own: an optimal
assignment of the whole problem is an optimal assignment of each component (they share
no plot and no centre), so when the optimum is unique — always, but for exact ties of
sums of costs — it is the same assignment as the dense one. Two caps bound a burst's
time, each counted: :data:`MAX_CANDIDATES` and :data:`MAX_EXACT_ROWS`.
"""

from __future__ import annotations

import numpy as np

from mhtrack.models.linalg2 import lmax2, mahalanobis2

#: Up to this many entries an assignment problem is solved on one dense matrix (32 MiB).
DENSE_ENTRIES = 1 << 22
#: In a sparse assignment each plot keeps at most this many cheapest allowed centres (a
#: cap, counted: ``fusion_candidates``).
MAX_CANDIDATES = 16
#: A connected component of more plots than this (beyond :data:`DENSE_ENTRIES`) is
#: assigned greedily, cheapest pair first (a cap, counted: ``fusion_greedy``); the exact
#: sparse solver's time grows as the square of the component.
MAX_EXACT_ROWS = 2000
#: Plots per chunk of the pair search (bounds its temporary arrays).
CHUNK = 4096


def allowed_pairs(
    z: np.ndarray, centres: np.ndarray, eps: float,
    R: np.ndarray | None, Rc: np.ndarray | None, gamma: float | None,
    max_per_plot: int = MAX_CANDIDATES,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, int]:
    """The allowed pairs of :func:`gated_assignment`: plot
    ``i`` and centre ``j`` with ``‖z_i − c_j‖ ≤ ε`` or (with ``R``, ``Rc``, ``γ``)
    ``(z_i − c_j)ᵀ (R_i + R̄c_j)⁻¹ (z_i − c_j) ≤ γ``, and their costs (same formulas).

    Candidates come from k-d trees within a radius of at least each plot's own
    ``max(ε, √(γ (λmax R_i + max_j λmax R̄c_j)))`` (the Mahalanobis gate lies inside it),
    :data:`CHUNK` plots of similar radii at a time, so memory is O(allowed pairs). A plot
    with more than ``max_per_plot`` allowed centres keeps the cheapest (ties: lower centre index).
    Returns ``(i, j, cost, stay, plots cut)``, pairs by plot then centre.
    """
    from scipy.spatial import cKDTree
    stat = R is not None and Rc is not None and gamma is not None
    m = len(z)
    if stat:
        r = np.sqrt(gamma * (lmax2(R) + lmax2(Rc).max()))  # type: ignore[operator,arg-type]
        radius = np.maximum(eps, r) * (1 + 1e-12) + 1e-9
        stay = float(gamma)  # type: ignore[arg-type]
    else:
        radius = np.full(m, eps * (1 + 1e-12) + 1e-9)
        stay = eps * eps
    tree = cKDTree(centres)
    parts: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    n_cut = 0
    by_radius = np.argsort(radius, kind="stable")  # chunks of similar radii
    for s0 in range(0, m, CHUNK):
        idx = by_radius[s0:s0 + CHUNK]
        near = cKDTree(z[idx]).sparse_distance_matrix(tree, float(radius[idx].max()),
                                                      output_type="ndarray")
        i, j = idx[near["i"]].astype(np.int64), near["j"].astype(np.int64)
        delta = z[i] - centres[j]
        d2 = (delta**2).sum(-1)
        allowed = d2 <= eps * eps
        if stat:
            dm, _ = mahalanobis2(delta, R[i] + Rc[j])  # type: ignore[index]
            allowed |= dm <= gamma
            cost = np.minimum(dm, stay * (1 - 1e-9))  # allowed by ε only: just below stay
        else:
            cost = d2
        i, j, cost = i[allowed], j[allowed], cost[allowed]
        o = np.lexsort((j, cost, i))  # per plot: cheapest first
        i, j, cost = i[o], j[o], cost[o]
        rank = np.arange(i.size) - np.searchsorted(i, i)
        if i.size and rank.max() >= max_per_plot:
            n_cut += int(np.count_nonzero(rank == max_per_plot))
            keep = rank < max_per_plot
            i, j, cost = i[keep], j[keep], cost[keep]
        parts.append((i, j, cost))
    i, j, cost = (np.concatenate([p[q] for p in parts]) for q in range(3))
    o = np.lexsort((j, i))
    return i[o], j[o], cost[o], stay, n_cut


def assign_dense(allowed: np.ndarray, cost: np.ndarray, stay: float) -> np.ndarray:
    """Optimal one-to-one assignment of rows to columns on a dense (m, c) problem: row
    ``i`` takes an ``allowed`` column at ``cost`` or stays alone at ``stay``
    (``linear_sum_assignment`` on ``[cost | stay·I]`` with disallowed entries
    ``2·stay + 1``). Returns the column per row or ``−1``."""
    from scipy.optimize import linear_sum_assignment
    m, c = allowed.shape
    out = np.full(m, -1, np.int64)
    big = 2.0 * stay + 1.0
    full = np.full((m, c + m), big)
    full[:, :c] = np.where(allowed, cost, big)
    full[np.arange(m), c + np.arange(m)] = stay  # "open a new cluster"
    r, col = linear_sum_assignment(full)
    hit = (col < c) & (full[r, col] < big)
    out[r[hit]] = col[hit]
    return out


def _assign_sparse(rows: np.ndarray, cols: np.ndarray, cost: np.ndarray, m: int, c: int,
                   stay: float) -> np.ndarray:
    """:func:`assign_dense` on the allowed pairs alone (LAPJVsp,
    ``min_weight_full_bipartite_matching``); every cost shifted by 1 (a row is matched
    exactly once, so the optimum is unchanged) to keep them non-zero."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import min_weight_full_bipartite_matching
    out = np.full(m, -1, np.int64)
    r = np.concatenate((rows, np.arange(m)))
    k = np.concatenate((cols, c + np.arange(m)))
    w = np.concatenate((cost, np.full(m, stay))) + 1.0
    g = csr_matrix((w, (r, k)), shape=(m, c + m))
    ri, ci = min_weight_full_bipartite_matching(g)
    hit = ci < c
    out[ri[hit]] = ci[hit]
    return out


def _assign_greedy(rows: np.ndarray, cols: np.ndarray, cost: np.ndarray, m: int,
                   stay: float) -> np.ndarray:
    """Greedy assignment: pairs by increasing cost (ties: row, then column), each taken
    when its row and column are both free and its cost is below ``stay``."""
    out = np.full(m, -1, np.int64)
    o = np.lexsort((cols, rows, cost))
    used: set[int] = set()
    for r, c, w in zip(rows[o].tolist(), cols[o].tolist(), cost[o].tolist(), strict=True):
        if w >= stay:
            break
        if out[r] < 0 and c not in used:
            out[r] = c
            used.add(c)
    return out


def sparse_gated_assignment(
    z: np.ndarray, centres: np.ndarray, eps: float,
    R: np.ndarray | None, Rc: np.ndarray | None, gamma: float | None,
    caps: dict[str, int] | None = None,
) -> np.ndarray:
    """The assignment of :func:`gated_assignment` (same gate,
    costs and ``stay``) from the allowed pairs alone (:func:`allowed_pairs`), then one
    exact problem per connected component of the allowed pairs (dense up to
    :data:`DENSE_ENTRIES` entries, else sparse). A component of one plot takes its cheapest
    allowed centre when that is strictly cheapest and below ``stay`` (what the solver
    would do), without calling the solver.

    Caps, for clutter bursts (counted in ``caps`` when given): each plot keeps its
    :data:`MAX_CANDIDATES` cheapest allowed centres (``fusion_candidates``: plots that had
    more); a component of more than :data:`MAX_EXACT_ROWS` plots (that does
    not fit :data:`DENSE_ENTRIES`) is assigned greedily (``fusion_greedy``: its plots)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    m = len(z)
    out = np.full(m, -1, np.int64)
    i, j, cost, stay, n_cut = allowed_pairs(z, centres, eps, R, Rc, gamma)
    if n_cut and caps is not None:
        caps["fusion_candidates"] = caps.get("fusion_candidates", 0) + n_cut
    if i.size == 0:
        return out
    # components of the bipartite graph plots (0..m−1) – centres (m..m+c−1)
    c = len(centres)
    g = coo_matrix((np.ones(i.size, np.int8), (i, m + j)), shape=(m + c, m + c))
    label = connected_components(g, directed=False)[1]
    comp = label[i]
    o = np.argsort(comp, kind="stable")  # edges grouped by component, order kept within
    i, j, cost, comp = i[o], j[o], cost[o], comp[o]
    starts = np.flatnonzero(np.r_[True, comp[1:] != comp[:-1]])
    ends = np.r_[starts[1:], comp.size]
    # a component of one plot: its cheapest centre when strictly cheapest and below stay
    one = i[starts] == i[ends - 1]
    best = np.minimum.reduceat(cost, starts)
    at_best = cost == best[np.repeat(np.arange(starts.size), ends - starts)]
    n_best = np.add.reduceat(at_best.astype(np.int64), starts)
    easy = one & (n_best == 1) & (best < stay)
    if easy.any():
        e = np.flatnonzero(at_best & np.repeat(easy, ends - starts))
        out[i[e]] = j[e]
    for s, e in zip(starts[~easy].tolist(), ends[~easy].tolist(), strict=True):
        ri, rj, rc = i[s:e], j[s:e], cost[s:e]
        ur, ir = np.unique(ri, return_inverse=True)
        uc, ic = np.unique(rj, return_inverse=True)
        if ur.size * (uc.size + ur.size) <= DENSE_ENTRIES:
            allow = np.zeros((ur.size, uc.size), bool)
            cm = np.zeros((ur.size, uc.size))
            allow[ir, ic] = True
            cm[ir, ic] = rc
            a = assign_dense(allow, cm, stay)
        elif ur.size <= MAX_EXACT_ROWS:
            a = _assign_sparse(ir, ic, rc, ur.size, uc.size, stay)
        else:
            a = _assign_greedy(ir, ic, rc, ur.size, stay)
            if caps is not None:
                caps["fusion_greedy"] = caps.get("fusion_greedy", 0) + int(ur.size)
        hit = a >= 0
        out[ur[hit]] = uc[a[hit]]
    return out


def gated_assignment(
    z: np.ndarray,
    centres: np.ndarray,
    eps: float,
    R: np.ndarray | None = None,
    Rc: np.ndarray | None = None,
    gamma: float | None = None,
    caps: dict[str, int] | None = None,
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
    Above :data:`DENSE_ENTRIES` entries: :func:`sparse_gated_assignment` (its caps are
    counted in ``caps``).
    """
    from scipy.spatial import cKDTree
    m = len(z)
    out = np.full(m, -1, np.int64)
    if m == 0 or len(centres) == 0:
        return out
    stat = R is not None and Rc is not None and gamma is not None
    radius = eps
    if stat:
        radius = max(eps, float(np.sqrt(gamma * (lmax2(R).max() + lmax2(Rc).max()))))
    if m * (len(centres) + m) > DENSE_ENTRIES:  # a burst: the allowed pairs alone
        return sparse_gated_assignment(z, centres, eps, R, Rc, gamma, caps)
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
    a = assign_dense(allowed, cost, stay)
    hit = a >= 0
    out[hit] = cols[a[hit]]
    return out
