"""CLEAR-MOT: multiple-object tracking accuracy (MOTA) and precision (MOTP).

Bernardin & Stiefelhagen (2008), "Evaluating multiple object tracking performance: the
CLEAR MOT metrics", EURASIP J. Image and Video Processing 2008:246309 — the per-frame
mapping procedure and the MOTP and MOTA definitions. Matching details, identity
switches and fragmentations follow ``motmetrics`` 1.4.0 (``MOTAccumulator.update`` and
``metrics.num_fragmentations``) so that results can be checked against it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mhtrack.metrics._common import (
    ScanIndexed,
    check_match_distance,
    check_tables,
    pairwise_distance,
    scan_union,
)
from mhtrack.records import TrackTable, TruthTable

#: Default matching distance ``d_match`` (m): a truth and a track farther apart than this
#: are never matched. Our choice (not from the papers): about 5σ of P1's measurement noise
#: (σw = 100 m) — a track this far from its target does not follow it.
DEFAULT_MATCH_DISTANCE = 500.0


@dataclass(frozen=True)
class MOTMatching:
    """Truth↔track correspondences, one row per matched pair, sorted by scan then target.

    ``distance`` is the Euclidean position distance (m); ``is_switch`` marks the pairs
    counted as identity switches.
    """

    scan: np.ndarray
    target_id: np.ndarray
    track_id: np.ndarray
    distance: np.ndarray
    is_switch: np.ndarray

    def __len__(self) -> int:
        return len(self.scan)


@dataclass(frozen=True)
class CLEARMOTResult:
    """CLEAR-MOT scores and counts.

    Attributes
    ----------
    mota : float
        ``1 − (n_misses + n_false + id_switches) / n_truth`` (NaN when ``n_truth == 0``).
    motp : float
        Mean distance (m) of the matched pairs (NaN when there is none).
    id_switches, fragmentations : int
        See :func:`clear_mot`.
    n_matches : int
        Matched pairs, identity switches included (motmetrics' ``num_detections``;
        its ``num_matches`` is ``n_matches − id_switches``).
    n_misses, n_false, n_truth : int
        False negatives, false positives and truth rows (GT).
    match_distance : float
        The matching distance used (m).
    matching : MOTMatching
        The per-scan correspondences.
    """

    mota: float
    motp: float
    id_switches: int
    fragmentations: int
    n_matches: int
    n_misses: int
    n_false: int
    n_truth: int
    match_distance: float
    matching: MOTMatching


def clear_mot(
    tracks: TrackTable,
    truth: TruthTable,
    *,
    match_distance: float = DEFAULT_MATCH_DISTANCE,
) -> CLEARMOTResult:
    r"""CLEAR-MOT metrics of ``tracks`` against ``truth`` with a distance gate.

    At every scan (in increasing order), with ``d`` the Euclidean distance between truth
    and track positions and ``d_match = match_distance``:

    1. *Keep correspondences.* Each truth remembers the track it was last matched to (at
       the last scan where it was matched; the memory survives scans at which it was
       missed, as in motmetrics — for a truth matched at the previous scan this is that
       scan's correspondence). The pair is kept if that track is reported at this scan
       and ``d <= d_match``. If two truths remember the same track, the one with the
       smaller target id keeps it.
    2. *Match the rest* with :func:`scipy.optimize.linear_sum_assignment` on ``d``,
       pairs with ``d > d_match`` forbidden: the most pairs, then the least total ``d``.
    3. A new pair ``(o, h)`` is an **identity switch** if ``o`` remembers a track other
       than ``h`` (however long ago; motmetrics' default ``max_switch_time = inf``).
    4. Unmatched truths are misses (FN), unmatched tracks false positives (FP).

    Then (Bernardin & Stiefelhagen 2008)

    .. math::
        \mathrm{MOTA} = 1 - \frac{\sum_k (FN_k + FP_k + IDSW_k)}{\sum_k GT_k},\qquad
        \mathrm{MOTP} = \frac{\sum_{k,i} d_{k,i}}{\sum_k c_k}

    with ``GT_k`` the number of truths and ``c_k`` of matched pairs at scan ``k``.

    **Fragmentations** follow motmetrics 1.4.0 ``num_fragmentations``: for each target,
    over the scans at which it exists, the number of transitions from matched to missed
    that lie between its first and last matched scan — i.e. the number of times its
    trajectory goes from tracked to untracked *and is tracked again later*. A gap in the
    truth itself (target absent) is not a miss.

    Parameters
    ----------
    tracks : TrackTable
    truth : TruthTable
    match_distance : float, default 500.0
        ``d_match`` in metres (``> 0``; ``inf`` lets any pair match).

    Returns
    -------
    CLEARMOTResult
    """
    tracks, truth = check_tables(tracks, truth)
    d_match = check_match_distance(match_distance, "match_distance")
    return clear_mot_indexed(ScanIndexed.build(tracks, truth,
                                               scan_union(truth.scan, tracks.scan)), d_match)


def clear_mot_indexed(data: ScanIndexed, d_match: float) -> CLEARMOTResult:
    """:func:`clear_mot` on checked, scan-indexed tables and a checked ``d_match`` (scans
    of ``data`` with no truth or no track match nothing)."""
    tracks, truth, scans = data.tracks, data.truth, data.scans
    t_index, k_index = data.truth_rows, data.track_rows
    targets, target_dense = np.unique(np.asarray(truth.target_id, np.int64), return_inverse=True)
    track_id = np.asarray(tracks.track_id, np.int64)
    t_pos, k_pos = truth.positions, tracks.positions

    remembered = np.zeros(len(targets), np.int64)  # last matched track id per target
    has_memory = np.zeros(len(targets), bool)
    matched_row = np.zeros(len(truth), bool)
    parts: list[tuple[np.ndarray, ...]] = []

    for k, scan in enumerate(scans.tolist()):
        rt, rk = t_index.rows(k), k_index.rows(k)
        if len(rt) == 0 or len(rk) == 0:
            continue
        D = pairwise_distance(t_pos[rt], k_pos[rk])
        tgt, kid = target_dense[rt], track_id[rk]
        i, j = _match_scan(D, d_match, remembered[tgt], has_memory[tgt], kid)
        tgt_i, kid_j = tgt[i], kid[j]
        switch = has_memory[tgt_i] & (remembered[tgt_i] != kid_j)
        remembered[tgt_i] = kid_j
        has_memory[tgt_i] = True
        matched_row[rt[i]] = True
        parts.append((np.full(len(i), scan, np.int64), targets[tgt_i], kid_j, D[i, j], switch))

    if parts:
        cols = [np.concatenate(c) for c in zip(*parts, strict=True)]
    else:
        cols = [np.zeros(0, np.int64)] * 3 + [np.zeros(0), np.zeros(0, bool)]
    matching = MOTMatching(*cols)

    n_truth, n_matches = len(truth), len(matching)
    n_misses, n_false = n_truth - n_matches, len(tracks) - n_matches
    id_switches = int(np.count_nonzero(matching.is_switch))
    mota = 1.0 - (n_misses + n_false + id_switches) / n_truth if n_truth else float("nan")
    motp = float(np.mean(matching.distance)) if n_matches else float("nan")
    return CLEARMOTResult(
        mota=float(mota),
        motp=motp,
        id_switches=id_switches,
        fragmentations=_fragmentations(target_dense, truth.scan, matched_row, len(targets)),
        n_matches=n_matches,
        n_misses=n_misses,
        n_false=n_false,
        n_truth=n_truth,
        match_distance=d_match,
        matching=matching,
    )


def _match_scan(
    D: np.ndarray,
    d_match: float,
    remembered: np.ndarray,
    has_memory: np.ndarray,
    kid: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Row/column indices of the matched pairs of one scan (steps 1–2 of :func:`clear_mot`).

    Rows of ``D`` are truths in ascending target id, columns tracks in ascending id ``kid``.
    """
    from scipy.optimize import linear_sum_assignment
    nt, nk = D.shape
    allowed = np.less_equal(D, d_match)
    # 1. keep remembered correspondences still within d_match
    col = np.minimum(np.searchsorted(kid, remembered), nk - 1)
    keep = has_memory & (kid[col] == remembered) & allowed[np.arange(nt), col]
    i1 = np.flatnonzero(keep)
    _, first = np.unique(col[i1], return_index=True)  # a track kept by one truth only
    i1 = i1[first]
    j1 = col[i1]
    # 2. optimal assignment of the others, forbidden pairs priced out of any optimum
    free_i = np.setdiff1d(np.arange(nt), i1)
    free_j = np.setdiff1d(np.arange(nk), j1)
    sub = D[np.ix_(free_i, free_j)]
    ok = allowed[np.ix_(free_i, free_j)]
    if ok.any():
        # one forbidden pair costs more than any feasible set of pairs (motmetrics.lap)
        big = 2.0 * min(sub.shape) * (sub[ok].max() + 1.0) + 1.0
        a, b = linear_sum_assignment(np.where(ok, sub, big))
        good = ok[a, b]
        i2, j2 = free_i[a[good]], free_j[b[good]]
    else:
        i2 = j2 = np.zeros(0, np.int64)
    i, j = np.concatenate((i1, i2)), np.concatenate((j1, j2))
    order = np.argsort(i, kind="stable")
    return i[order], j[order]


def _fragmentations(
    target_dense: np.ndarray, scan: np.ndarray, matched: np.ndarray, n_targets: int
) -> int:
    """Matched→missed transitions of each target before its last matched scan."""
    if len(scan) == 0:
        return 0
    order = np.lexsort((np.asarray(scan), target_dense))
    g, m = target_dense[order], matched[order]
    pos = np.arange(len(order))
    last_matched = np.full(n_targets, -1, np.int64)
    np.maximum.at(last_matched, g[m], pos[m])
    frag = (g[1:] == g[:-1]) & m[:-1] & ~m[1:] & (pos[1:] < last_matched[g[1:]])
    return int(np.count_nonzero(frag))
