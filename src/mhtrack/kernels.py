"""Code kept only for speed, in one place: NumPy idioms and one unrolled loop. Each gives
bit for bit what the plain form in its docstring gives (``tests/test_kernels.py``,
``tests/mht/test_bnb.py``) and says what it saves, measured on ``crossing`` with MHT-AGMM
(90 scans, ~1.3 ms a scan; calls counted in the cycle, ``timeit`` medians on a scan's
sizes) unless it says otherwise. Where a trick saved less than 1 % of a scan the plain
form is used instead (``docs/performance.md``, *Speed idioms in one place*).
"""

from __future__ import annotations

import numpy as np

#: ``a.sum(axis)``, ``a.min(axis)``, ``a.max(axis)``, ``a.all(axis)``, ``a.any(axis)``:
#: NumPy's reductions called directly, without the methods' Python wrappers — the same
#: results. ``sum_(w)`` of a mixture's few weights 0.65 against 1.43 µs, of a (9, 300)
#: array 1.85 against 2.07 µs, ``all_`` of a scan's (n, 2) mask 0.6 against 1.1 µs; ~45
#: calls a scan in the clutter estimator (:mod:`mhtrack.clutter`), ~1.3 % of a scan.
sum_, min_, max_ = np.add.reduce, np.minimum.reduce, np.maximum.reduce
all_, any_ = np.logical_and.reduce, np.logical_or.reduce


def mean(a: np.ndarray) -> float:
    """``a.mean()`` of a 1-D float array: its sum divided by its length, ndarray.mean's own
    formula, without the method's dispatch.

    1.0 against 3.1 µs on 300 plots; ~6 calls a scan (EM's log-likelihood), ~1 %; two
    a radar's frame (the beam's circular mean, :mod:`mhtrack.mht.coverage`)."""
    return sum_(a) / len(a)


def changes(sorted_keys: np.ndarray) -> np.ndarray:
    """Mask over the rows of ``sorted_keys``: the row starts a run of equal values (the
    first row always); ``np.r_[True, k[1:] != k[:-1]]``.

    Saves ~2 µs a call (1.0 against 3.0 µs on 50 keys: no index-trick set-up); ~14 calls
    a scan, ~2 % of it."""
    flag = np.empty(sorted_keys.size, bool)
    flag[:1] = True
    np.not_equal(sorted_keys[1:], sorted_keys[:-1], out=flag[1:])
    return flag


def segment_sizes(starts: np.ndarray, n: int) -> np.ndarray:
    """Rows of each segment from its ``starts`` over ``n`` rows: ``np.diff(np.r_[starts,
    n])``.

    2.6 against 7.9 µs on 15 segments (no index-trick set-up); ~3 calls a scan, ~1.2 %."""
    sizes = np.empty(starts.size, np.int64)
    np.subtract(starts[1:], starts[:-1], out=sizes[:-1])
    sizes[-1:] = n - starts[-1:]
    return sizes


def cov_biased(z: np.ndarray) -> np.ndarray:
    """``np.cov(z.T, bias=True)`` of (n ≥ 2, 2) points: NumPy's own steps for this case
    (copy, subtract the row means, ``dot(X, Xᵀ)``, times ``1/n``) without its argument
    handling — the same floats.

    11.6 against 25.7 µs on 30 points; ~0.9 calls a scan (a k-means++ start of new
    clutter components), ~1 %."""
    x = np.array(z.T, ndmin=2, dtype=np.float64)
    x -= (sum_(x, axis=1) / x.shape[1])[:, None]
    c = np.dot(x, x.T.conj())
    c *= np.true_divide(1, x.shape[1])
    return c


def same_floats(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether ``a`` and ``b`` hold the same floats bit for bit, in the same shape (the
    key of a one-scan cache: ``-0.0`` and ``0.0`` differ, a NaN equals itself).

    A byte comparison: ~1 µs on a scan's plots; the cache it keys
    (:meth:`mhtrack.clutter.mixture.MixtureClutter.intensity`) saves a density evaluation
    of every plot of the scan."""
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def two_tree_search(a_opts: list[tuple[float, int, int]],
                    b_opts: list[tuple[float, int, int]]) -> list[int]:
    """:func:`mhtrack.mht.bnb.search` on the two trees of a cluster, unrolled: each
    tree's options ``(score, plot mask, leaf)`` best first, tree ``a_opts`` the one the
    search visits first; the same nodes in the same order, the same sums and comparisons,
    hence the same chosen leaves (``tests/mht/test_bnb.py``). The caller makes sure the
    search cannot pass its node limit (``1 + (p + 1)(q + 2)`` nodes at most).

    On an hour of three radars (``bench_async.py --hour``, first 600 s): 8.5 calls a frame,
    12 against 45 µs a frame, ~3 % of it (crossing: 0.4 calls a scan, 1 µs)."""
    a1, m1, i1 = a_opts[0]
    b1 = b_opts[0][0]
    # greedy incumbent: A's best, then B's first leaf compatible with it
    best_val, best_sel = a1, [i1]  # 0.0 + a1
    for sc, m, i in b_opts:
        if not m & m1:
            best_val += sc
            best_sel.append(i)
            break
    if b1 + a1 <= best_val:  # the root: 0.0 + bound[0], bound[0] = (0.0 + b1) + a1
        return best_sel
    for sa, ma, ia in a_opts:
        if sa + b1 <= best_val:  # node (A takes ia): its total plus bound[1] = b1
            continue
        for sb, mb, ib in b_opts:  # B's compatible leaves in order, then "none"
            if not mb & ma and sa + sb > best_val:
                best_val, best_sel = sa + sb, [ia, ib]
        if sa > best_val:
            best_val, best_sel = sa, [ia]
    # "leave A out" is pruned at its node: 0.0 + b1 <= a1 <= best_val
    return best_sel
