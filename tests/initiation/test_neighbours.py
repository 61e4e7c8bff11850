"""The clustering's pair searches without all-pairs matrices, against brute force and the
dense implementation they replace (tests/reference/dense_kmeans.py)."""

from __future__ import annotations

import tracemalloc
from collections.abc import Iterator
from contextlib import contextmanager

import dense_kmeans as ref
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.distance import pdist

import mhtrack.initiation.assignment as asg
import mhtrack.initiation.neighbours as nb
from mhtrack.initiation import AdaptiveKMeansFusion
from mhtrack.initiation.assignment import allowed_pairs, gated_assignment
from mhtrack.initiation.kmeans import (
    Gate,
    adaptive_initial_centres,
    enforce_one_plot_per_sensor,
)
from mhtrack.initiation.neighbours import SortedDistances, close_pairs, pair_distances
from mhtrack.models.linalg2 import mahalanobis2


@contextmanager
def patched(*changes: tuple[object, str, object]) -> Iterator[None]:
    """Module constants changed for the body (hypothesis runs many inputs per test, so
    no function-scoped ``monkeypatch``)."""
    with pytest.MonkeyPatch.context() as mp:
        for mod, name, value in changes:
            mp.setattr(mod, name, value)
        yield


#: Every search and assignment through the k-d tree code, however small.
SPARSE = ((nb, "DENSE_PAIRS", 0), (asg, "DENSE_ENTRIES", 0), (asg, "CHUNK", 7))


def _points(seed: int, n: int, grid: bool) -> np.ndarray:
    rng = np.random.default_rng(seed)
    z = rng.uniform(0, 2000, (n, 2))
    return np.round(z / 100) * 100 if grid else z  # grid: many exact ties and duplicates


def _scan(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Plots of 1–3 radars round a few targets plus clutter, with covariances."""
    rng = np.random.default_rng(seed)
    nt, ns = int(rng.integers(1, 25)), int(rng.integers(1, 4))
    truth = rng.uniform(0, 3000, (nt, 2))
    z, s, R = [], [], []
    for k in range(ns):
        det = rng.random(nt) < 0.9
        sig = rng.uniform(10, 80)
        n_cl = int(rng.poisson(8))
        z += [truth[det] + rng.normal(0, sig, (int(det.sum()), 2)),
              rng.uniform(0, 3000, (n_cl, 2))]
        m = int(det.sum()) + n_cl
        s += [k] * m
        a = rng.uniform(0.5, 2.0, m)
        R += [np.array([[sig**2 * x, 0.3 * sig**2], [0.3 * sig**2, 1.5 * sig**2]]) for x in a]
    return np.concatenate(z), np.array(s), np.array(R).reshape(-1, 2, 2)


def test_pair_distances_are_pdists_bits():
    z = np.random.default_rng(0).normal(0, 1e4, (300, 2))
    i, j = np.triu_indices(300, 1)
    assert np.array_equal(pair_distances(z, i, j), pdist(z))


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10**6), n=st.integers(2, 80), grid=st.booleans(),
       per=st.integers(1, 3), capped=st.booleans())
def test_sorted_distances_read_as_the_full_sort(seed, n, grid, per, capped):
    z = _points(seed, n, grid)
    full = np.sort(pdist(z))
    need = min(per * n, len(full))
    cap = float(np.median(full)) if capped else None
    with patched((nb, "DENSE_PAIRS", 0)):
        D = SortedDistances(z, need, cap)
    assert len(D) == len(full)
    for i in range(need):
        if cap is None:
            assert D[i] == full[i]
        else:
            assert min(D[i], cap) == min(full[i], cap)


def test_sorted_distances_of_coincident_plots():
    z = np.vstack((np.zeros((50, 2)), [[3.0, 4.0]]))
    with patched((nb, "DENSE_PAIRS", 0)):
        D = SortedDistances(z, 51)
    assert [D[i] for i in range(51)] == [0.0] * 51
    with pytest.raises(IndexError):
        D[len(D)]


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10**6), n=st.integers(2, 60))
def test_close_pairs_in_chunks_are_the_brute_force_pairs(seed, n):
    rng = np.random.default_rng(seed)
    z = rng.uniform(0, 1000, (n, 2))
    own = rng.uniform(50, 400, n)
    i, j = np.triu_indices(n, 1)
    d = pair_distances(z, i, j)
    ok = d <= np.minimum(own[i], own[j])  # a gate that each point's own radius bounds
    expect = {(a, b) for a, b in zip(i[ok].tolist(), j[ok].tolist(), strict=True)}

    def keep(p: np.ndarray) -> np.ndarray:
        return pair_distances(z, p[:, 0], p[:, 1]) <= np.minimum(own[p[:, 0]], own[p[:, 1]])

    with patched((nb, "DENSE_PAIRS", 0), (nb, "PAIRS_PER_POINT", 0), (nb, "CHUNK", 5)):
        got = close_pairs(z, 400.0, own, keep)
    assert {tuple(p) for p in got.tolist()} == expect
    assert np.array_equal(got, got[np.lexsort((got[:, 1], got[:, 0]))])


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10**6), stat=st.booleans())
def test_allowed_pairs_are_the_brute_force_gate(seed, stat):
    rng = np.random.default_rng(seed)
    m, c = int(rng.integers(1, 40)), int(rng.integers(1, 40))
    z, cen = rng.uniform(0, 2000, (m, 2)), rng.uniform(0, 2000, (c, 2))
    A = rng.normal(size=(m + c, 2, 2))
    cov = A @ np.swapaxes(A, 1, 2) * rng.uniform(100, 5e4) + 10 * np.eye(2)
    R, Rc = (cov[:m], cov[m:]) if stat else (None, None)
    eps, gamma = float(rng.uniform(0, 500)), (18.42 if stat else None)
    with patched((asg, "CHUNK", 6)):
        i, j, cost, stay, cut = allowed_pairs(z, cen, eps, R, Rc, gamma, max_per_plot=10**6)
    # brute force: every pair, the dense formulas of gated_assignment
    delta = z[:, None, :] - cen[None, :, :]
    d2 = (delta**2).sum(-1)
    ok = d2 <= eps * eps
    expect_cost = d2
    if stat:
        dm, _ = mahalanobis2(delta, R[:, None] + Rc[None, :])
        ok |= dm <= gamma
        expect_cost = np.minimum(dm, gamma * (1 - 1e-9))
    bi, bj = np.nonzero(ok)
    assert cut == 0
    assert np.array_equal(i, bi) and np.array_equal(j, bj)
    assert np.array_equal(cost, expect_cost[bi, bj])
    assert stay == (gamma if stat else eps * eps)


# Exact ties of assignment costs (plots on a grid, or several pairs allowed by the
# Euclidean ε alone, which all cost γ⁻) may be broken otherwise by the components'
# solver: an optimal assignment still (test_an_assignment_with_ties_is_still_optimal).
# Without ties the clusters are the dense code's, bit for bit: the Euclidean gate alone
# (no covariances), or the covariance gate with ε below every distance.


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 10**6), stat=st.booleans())
def test_kmeans_steps_equal_the_dense_implementation(seed, stat):
    z, s, R = _scan(seed)
    Rr, gamma, cap = (R, 18.420680743952367, 1e-3) if stat else (None, None, None)
    c_ref, lab_ref, eps_ref = ref.adaptive_initial_centres(z, s, R=Rr, gamma=gamma,
                                                           max_threshold=cap)
    with patched(*SPARSE):
        c, lab, eps = adaptive_initial_centres(z, s, R=Rr, gamma=gamma, max_threshold=cap)
        fixed = enforce_one_plot_per_sensor(z, s, lab, Gate(eps, Rr, gamma))
    assert eps == eps_ref
    assert np.array_equal(lab, lab_ref)
    assert np.array_equal(c, c_ref, equal_nan=True)
    assert np.array_equal(fixed, ref.enforce_one_plot_per_sensor(z, s, lab, eps, Rr, gamma))


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10**6), stat=st.booleans(),
       consistency=st.sampled_from([None, 0.9999]))
def test_adaptive_fusion_equals_the_dense_implementation(seed, stat, consistency):
    z, s, R = _scan(seed)
    p, cap = (0.9999, 1e-3) if stat else (None, None)
    with patched(*SPARSE):
        f = AdaptiveKMeansFusion(merge_probability=p, max_threshold=cap,
                                 consistency=consistency).fit(z, s, R)
    labels, eps = ref.adaptive_fit(z, s, R, p, cap, consistency)
    assert np.array_equal(f.labels_, labels)
    assert f.threshold_ == eps
    assert f.caps_ == {}


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10**6), grid=st.booleans())
def test_an_assignment_with_ties_is_still_optimal(seed, grid):
    """Ties (grid plots; pairs allowed by ε alone, each costing γ⁻): the components'
    assignment may differ from the dense one, but not in total cost."""
    rng = np.random.default_rng(seed)
    m, k = int(rng.integers(1, 40)), int(rng.integers(1, 40))
    z, c = rng.uniform(0, 1000, (m, 2)), rng.uniform(0, 1000, (k, 2))
    if grid:
        z, c = np.round(z / 100) * 100, np.round(c / 100) * 100
    A = rng.normal(size=(m + k, 2, 2))
    cov = A @ np.swapaxes(A, 1, 2) * 200 + 10 * np.eye(2)
    R, Rc, gamma = cov[:m], cov[m:], 18.420680743952367
    eps = float(rng.uniform(50, 300))

    def cost(a: np.ndarray) -> float:
        """Σ min(d², γ⁻) over joined plots + γ per plot alone (gated_assignment)."""
        j = np.maximum(a, 0)
        delta = z - c[j]
        dm, _ = mahalanobis2(delta, R + Rc[j])
        return float(np.where(a >= 0, np.minimum(dm, gamma * (1 - 1e-9)), gamma).sum())

    with patched(*SPARSE):
        a = gated_assignment(z, c, eps, R, Rc, gamma)
    b = ref._gated_assignment(z, c, eps, R, Rc, gamma)
    assert len(set(a[a >= 0].tolist())) == int((a >= 0).sum())  # one plot per centre
    assert cost(a) == pytest.approx(cost(b), rel=1e-12, abs=1e-9)


def test_fusion_of_a_burst_takes_memory_in_the_plots_not_their_square():
    """20 000 plots of two radars: the dense code needed 1.6 GB for ``pdist`` alone."""
    rng = np.random.default_rng(0)
    n = 20_000
    z = rng.uniform(0, 200_000, (n, 2))
    s = np.repeat([1, 2], n // 2)
    R = np.broadcast_to(np.diag([2500.0, 40_000.0]), (n, 2, 2)).copy()
    tracemalloc.start()
    try:
        f = AdaptiveKMeansFusion(consistency=0.9999).fit(z, s, R)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 150 * 2**20
    # one plot per radar per cluster, every plot in a cluster
    assert np.bincount(f.labels_ * 3 + s).max() == 1
    assert f.labels_.min() == 0 and len(f.cluster_centers_) == f.labels_.max() + 1
