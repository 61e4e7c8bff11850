"""The N best global hypotheses of one cluster, by Murty's partitioning.

A cluster's global hypothesis chooses, for every tree, one of its leaves or none, such
that no two chosen leaves use the same plot; its score is the sum of the chosen leaves'
scores (P1 §1.3; Blackman & Popoli 1999 §16.3). Only leaves with a positive score take
part (as in :func:`~mhtrack.mht.hypothesis.best_hypothesis`; a leaf with score ≤ 0 is
the clutter side and gets probability 0).

Murty's method (Murty 1968, in Lawler's general form, Lawler 1972; Cox & Miller 1995 for
MHT) ranks the solutions of any problem whose best solution can be found under
constraints "tree ``t`` takes option ``o``" and "tree ``t`` does not take option ``o``":
with the best solution ``h = (o_1 … o_m)`` over the free trees ``f_1 … f_m`` of a
subproblem, the subproblem less ``h`` splits into ``m`` disjoint parts, part ``j`` fixing
``f_1 … f_{j−1}`` to ``o_1 … o_{j−1}`` and forbidding ``o_j`` for ``f_j``. A priority queue
of the parts' best solutions gives the next best hypothesis at each pop. Each part is
solved exactly by branch-and-bound over its free trees (the same search as
:func:`~mhtrack.mht.hypothesis.solve_exact`, with the constraints).

**Order and ties.** Hypotheses are ranked by total score, largest first, the total
computed with :func:`math.fsum` (exactly rounded, so independent of the order the scores
are added); equal totals are ranked by the ascending tuple of their sorted leaf indices,
smallest first. That order is total, every part is solved under it exactly, so the
ranking is the same as sorting all hypotheses by ``(−total, leaves)``: deterministic, and
what the tests compare with brute-force enumeration.
"""

from __future__ import annotations

import heapq
import itertools
import math

import numpy as np

from mhtrack.mht.clustering import plot_keys
from mhtrack.mht.tree import segment_starts

#: Branch-and-bound nodes all the parts' searches of one cluster may visit together
#: before the enumeration stops (a count, so the result does not depend on the machine).
NODE_LIMIT = 50_000
#: Slack (relative to the scores' scale) under which the search keeps exploring a branch
#: that could tie the incumbent: rounding in the running sums must not cut a tie.
TIE_SLACK = 1e-9

#: A hypothesis: the sorted leaf indices (within the problem) and its total score.
Ranked = tuple[tuple[int, ...], float]


def conflict_masks(window: np.ndarray, by_id: bool = False) -> list[int]:
    """Per leaf, a Python-int bitset of the plots it uses (bit ``k``: plot key ``k`` of
    :func:`~mhtrack.mht.clustering.plot_keys`)."""
    leaf, key = plot_keys(window, by_id=by_id)
    masks = [0] * len(window)
    for i, k in zip(leaf.tolist(), key.tolist(), strict=True):
        masks[i] |= 1 << k
    return masks


class _Limit(Exception):
    """The searches passed :data:`NODE_LIMIT`."""


class _Problem:
    """One cluster: per tree its options ``(score, mask, leaf)``, best first."""

    def __init__(self, score: np.ndarray, tree: np.ndarray, window: np.ndarray,
                 by_id: bool, node_limit: int) -> None:
        pos = np.flatnonzero(score > 0)
        s = score[pos]
        masks = conflict_masks(window[pos], by_id)
        order = np.lexsort((pos, -s, tree[pos]))
        starts = [*segment_starts(tree[pos][order]).tolist(), pos.size]
        self.options = [
            [(float(s[i]), masks[i], int(pos[i])) for i in order[a:b].tolist()]
            for a, b in itertools.pairwise(starts)
        ]
        self.score = {int(p): float(v) for p, v in zip(pos, s, strict=True)}
        self.tree_of = {i: t for t, opts in enumerate(self.options) for _, _, i in opts}
        self.mask_of = {i: m for opts in self.options for _, m, i in opts}
        self.slack = TIE_SLACK * (1.0 + float(s.sum()) if s.size else 1.0)
        self.node_limit = node_limit
        self.nodes = 0  # visited by all searches so far

    def key(self, leaves: tuple[int, ...]) -> tuple[float, tuple[int, ...]]:
        """Rank key: smaller is better."""
        return -math.fsum(self.score[i] for i in leaves), leaves

    def solve(self, fixed: dict[int, int | None],
              banned: dict[int, frozenset[int | None]]) -> dict[int, int | None] | None:
        """Best choice (tree → leaf or ``None``) with trees ``fixed`` and options
        ``banned``, or ``None`` if infeasible. Raises :class:`_Limit`."""
        used = 0
        for leaf in fixed.values():
            if leaf is not None:
                m = self.mask_of[leaf]
                if m & used:
                    return None
                used |= m
        free = []  # (tree, allowed options, none allowed)
        for t, opts in enumerate(self.options):
            if t in fixed:
                continue
            ban = banned.get(t, frozenset())
            allowed = [o for o in opts if o[2] not in ban and not o[1] & used]
            none_ok = None not in ban
            if not allowed and not none_ok:
                return None
            free.append((t, allowed, none_ok))
        # most valuable trees first; the bound is the sum of the remaining best options
        free.sort(key=lambda f: (-(f[1][0][0] if f[1] else 0.0), f[0]))
        bound = [0.0] * (len(free) + 1)
        for j in range(len(free) - 1, -1, -1):
            bound[j] = bound[j + 1] + (free[j][1][0][0] if free[j][1] else 0.0)
        base = tuple(sorted(i for i in fixed.values() if i is not None))
        base_val = sum(self.score[i] for i in base)
        best_key: tuple[float, tuple[int, ...]] | None = None
        best_sel: tuple[int, ...] = ()
        best_val = -math.inf
        stack: list[tuple[int, int, float, tuple[int, ...]]] = [(0, used, base_val, ())]
        while stack:
            j, u, val, sel = stack.pop()
            self.nodes += 1
            if self.nodes > self.node_limit:
                raise _Limit
            if val + bound[j] < best_val - self.slack:
                continue
            if j == len(free):
                k = self.key(tuple(sorted(base + sel)))
                if best_key is None or k < best_key:
                    best_key, best_sel, best_val = k, sel, val
                continue
            t, allowed, none_ok = free[j]
            if none_ok:  # pushed first: explored last
                stack.append((j + 1, u, val, sel))
            for sc, m, i in reversed(allowed):
                if not m & u:
                    stack.append((j + 1, u | m, val + sc, (*sel, i)))
        if best_key is None:
            return None
        choice: dict[int, int | None] = {t: None for t, _, _ in free}
        choice.update(fixed)
        for i in best_sel:
            choice[self.tree_of[i]] = i
        return choice


def n_best_hypotheses(
    score: np.ndarray, tree: np.ndarray, window: np.ndarray, n: int, *,
    by_id: bool = False, node_limit: int = NODE_LIMIT,
) -> tuple[list[Ranked], bool]:
    """The ``n`` best hypotheses of one cluster (module docstring), best first.

    Parameters
    ----------
    score, tree, window : the leaves, as :func:`~mhtrack.mht.hypothesis.best_hypothesis`.
    n : how many (fewer when the cluster has fewer hypotheses).
    by_id : plots identified by id alone (frames of several sensors).
    node_limit : nodes all the parts' searches may visit together.

    Returns
    -------
    ``([(leaf indices ascending, total), …], complete)``; ``complete`` is false when the
    searches passed ``node_limit`` — the list then holds the hypotheses ranked before
    that (correct, but perhaps fewer than ``n``; empty if the best was not found).
    """
    prob = _Problem(np.asarray(score, float), np.asarray(tree), np.asarray(window),
                    by_id, node_limit)
    out: list[Ranked] = []
    try:
        first = prob.solve({}, {})
    except _Limit:
        return out, False
    if first is None:  # cannot happen: "all trees left out" is always feasible
        return out, True
    heap = [(_key(prob, first), first, {}, {})]
    while heap and len(out) < n:
        (neg_total, leaves), choice, fixed, banned = heapq.heappop(heap)
        out.append((leaves, -neg_total))
        if len(out) == n:
            break
        free = [t for t in range(len(prob.options)) if t not in fixed]
        fix = dict(fixed)
        try:
            for t in free:
                ban = dict(banned)
                ban[t] = banned.get(t, frozenset()) | {choice[t]}
                part = prob.solve(fix, ban)
                if part is not None:
                    heapq.heappush(heap, (_key(prob, part), part, dict(fix), ban))
                fix[t] = choice[t]
        except _Limit:
            return out, False
    return out, True


def _key(prob: _Problem, choice: dict[int, int | None]) -> tuple[float, tuple[int, ...]]:
    return prob.key(tuple(sorted(i for i in choice.values() if i is not None)))
