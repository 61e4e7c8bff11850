"""P1 Table 3's association and track-continuity metrics: Rcc, Rmc, Rfg, Lmin/Lavg/Lmax.

P1 (§3, Table 3) reports a correct-association rate ``Rcc``, a mis-association rate
``Rmc``, a track fragmentation rate ``Rfg`` and the track life ``Lmin/Lavg/Lmax`` (s)
without defining them; the definitions below are ours, written so that they can be checked
by hand (``docs/metrics.md``).

Tracks are matched to targets per scan by the **CLEAR-MOT matching** of
:func:`mhtrack.metrics.clear_mot` (optimal assignment within the matching distance that
keeps a target's previous track while it stays within that distance), so these metrics
agree with the identity switches and fragmentations reported next to them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mhtrack.metrics._common import ScanIndexed, check_match_distance, check_tables, scan_union
from mhtrack.metrics.clearmot import DEFAULT_MATCH_DISTANCE, MOTMatching, clear_mot_indexed
from mhtrack.records import CLUTTER, NO_PLOT, PlotTable, TrackTable, TruthTable


@dataclass(frozen=True)
class AssociationResult:
    """P1 Table 3 metrics of one run (see :func:`association_metrics`).

    Attributes
    ----------
    rcc, rmc : float
        Correct- and mis-association rates, ``n_correct / n_detected`` and
        ``n_wrong / n_detected``; NaN without plot origins or when ``n_detected == 0``.
    rfg : float
        Track breaks per target, ``n_breaks / n_targets`` (NaN when there is no target).
    l_min, l_avg, l_max : float
        Min, mean and max over targets of ``life`` (s); NaN when there is no target.
    n_detected, n_correct, n_wrong : int
        ``(scan, target)`` pairs where the target produced a plot; those whose matched
        track used a plot of that target; those whose matched track used another plot.
        All 0 without plot origins.
    n_breaks, n_targets : int
        Track breaks summed over targets; distinct target ids in the truth.
    scan_period : float
        ``T`` (s) used for the track life.
    target_id, life, breaks : (n_targets,) arrays
        Per target (ascending id): longest time followed by one track (s), and its breaks.
    delay : (n_targets,) array
        Per target, its confirmation delay in scans (NaN if never confirmed).
    delay_mean, delay_max : float
        Mean and max of ``delay`` over the targets that were confirmed (NaN if none).
    has_origin : bool
        Whether plot origins were available (``rcc``/``rmc`` computed).
    """

    rcc: float
    rmc: float
    rfg: float
    l_min: float
    l_avg: float
    l_max: float
    n_detected: int
    n_correct: int
    n_wrong: int
    n_breaks: int
    n_targets: int
    scan_period: float
    target_id: np.ndarray
    life: np.ndarray
    breaks: np.ndarray
    has_origin: bool
    delay: np.ndarray | None = None

    @property
    def delay_mean(self) -> float:
        d = self.delay
        return float(np.nanmean(d)) if d is not None and np.isfinite(d).any() else float("nan")

    @property
    def delay_max(self) -> float:
        d = self.delay
        return float(np.nanmax(d)) if d is not None and np.isfinite(d).any() else float("nan")


def association_metrics(
    tracks: TrackTable,
    truth: TruthTable,
    plots: PlotTable | None = None,
    *,
    match_distance: float = DEFAULT_MATCH_DISTANCE,
    matching: MOTMatching | None = None,
    scan_period: float | None = None,
) -> AssociationResult:
    r"""P1 Table 3's Rcc, Rmc, Rfg and Lmin/Lavg/Lmax of ``tracks`` against ``truth``.

    **Matching.** At every scan each live target is matched to at most one track by the
    CLEAR-MOT matching (:func:`~mhtrack.metrics.clear_mot`, distance ``match_distance``);
    ``h(k, o)`` denotes the track matched to target ``o`` at scan ``k``, if any.

    **Rcc, Rmc** (need ``plots`` with ``origin``; the tracks' ``plot`` column is the row of
    ``plots`` each track used, ``-1`` on a miss). Let ``D`` be the set of ``(k, o)`` such
    that some plot of scan ``k`` has ``origin == o`` (the target was detected, by any
    sensor). Then

    .. math::
        R_{cc} = \frac{|\{(k, o) \in D : h(k,o) \text{ used a plot with origin } o\}|}{|D|},
        \qquad
        R_{mc} = \frac{|\{(k, o) \in D : h(k,o) \text{ used a plot with origin} \ne o\}|}{|D|}

    (``origin ≠ o``: clutter or another target's plot). The rest of ``D`` — target not
    matched, or its track coasted (``plot = -1``) — is in neither, so
    ``R_cc + R_mc ≤ 1``. Pairs outside ``D`` (target missed by every sensor) do not count.

    **Rfg.** For each target, walk its live scans (its truth rows, by scan; a gap in the
    truth is not a scan of its life) and count a **break** at each pair of consecutive
    live scans ``(k⁻, k)`` where it is matched at ``k⁻`` and at ``k`` is either unmatched
    or matched to a different track. Transitions from unmatched to matched are not
    breaks, so the scans before the first match (initiation delay) never count, and a
    loss then re-acquisition counts once.
    ``R_fg = Σ_o breaks(o) / n_targets``.

    **Track life.** A *run* of target ``o`` is a maximal sequence of consecutive live
    scans matched to one track id; its duration is ``time[last] − time[first] + T`` (the
    truth's ``time`` column; ``T`` is the scan period, so a one-scan run lasts ``T``).
    ``life(o)`` is the longest run's duration, 0 if ``o`` is never matched;
    ``L_min, L_avg, L_max`` are the min, mean and max of ``life`` over the targets.

    **Confirmation delay** (ours). ``delay(o)`` is the number of live scans of ``o``
    before the first one at which it is matched to a track in the *online view* of the
    tracks — the rows reported at their scan (``tracks.tentative`` false or absent), matched
    on their own by CLEAR-MOT: 0 when a track was reported on it at its first scan. Rows
    backfilled later (``tentative``, :mod:`mhtrack.mht.history`) count for the other
    metrics but not here, so the delay is the same for a history output and its online
    view: it measures when the tracker decided.

    Parameters
    ----------
    tracks : TrackTable
    truth : TruthTable
    plots : PlotTable, optional
        The plots the tracker was run on; ``rcc``/``rmc`` need its ``origin`` column.
    match_distance : float, default 500.0
        CLEAR-MOT ``d_match`` (m), used when ``matching`` is not given, and for the
        online view's matching of the confirmation delay.
    matching : MOTMatching, optional
        A precomputed ``clear_mot(tracks, truth).matching`` (as :func:`evaluate` does).
    scan_period : float, optional
        ``T`` (s). Default: the median of ``Δtime / Δscan`` over consecutive scans of
        ``plots.all_scan_times()`` (or of the truth when no plots are given); 0 when fewer
        than two scans are known.

    Returns
    -------
    AssociationResult

    Raises
    ------
    ValueError
        If a track's ``plot`` is not ``-1`` or a row of ``plots`` at the track's scan
        (checked when plot origins are given).
    """
    tracks, truth = check_tables(tracks, truth)
    if plots is not None and not isinstance(plots, PlotTable):
        raise TypeError(f"plots must be a PlotTable or None, got {type(plots).__name__}")
    data = ScanIndexed.build(tracks, truth, scan_union(truth.scan, tracks.scan))
    if matching is None:
        d_match = check_match_distance(match_distance, "match_distance")
        matching = clear_mot_indexed(data, d_match).matching
    return association_indexed(data, plots, matching, match_distance, scan_period)


def association_indexed(data: ScanIndexed, plots: PlotTable | None, matching: MOTMatching,
                        match_distance: float = DEFAULT_MATCH_DISTANCE,
                        scan_period: float | None = None) -> AssociationResult:
    """:func:`association_metrics` on checked, scan-indexed tables (``data.scans`` holding
    every scan of both) and ``plots`` (a :class:`PlotTable` or ``None``), given their
    CLEAR-MOT ``matching``."""
    tracks, truth = data.tracks, data.truth
    T = _scan_period(truth, plots) if scan_period is None else float(scan_period)

    has_origin = plots is not None and plots.origin is not None
    n_det = n_cor = n_wrong = 0
    if has_origin:
        assert plots is not None and plots.origin is not None
        n_det, n_cor, n_wrong = _association_counts(tracks, plots, matching)

    targets, breaks, life = _continuity(truth, matching, T)
    if tracks.tentative is not None and np.any(tracks.tentative):
        d_online = check_match_distance(match_distance, "match_distance")
        online_matching = clear_mot_indexed(data.with_tracks(tracks.online()),
                                            d_online).matching
        delay = _confirm_delay(truth, online_matching)
    else:
        delay = _confirm_delay(truth, matching)
    n_targets = len(targets)
    n_breaks = int(breaks.sum())
    nan = float("nan")
    return AssociationResult(
        rcc=n_cor / n_det if n_det else nan,
        rmc=n_wrong / n_det if n_det else nan,
        rfg=n_breaks / n_targets if n_targets else nan,
        l_min=float(life.min()) if n_targets else nan,
        l_avg=float(life.mean()) if n_targets else nan,
        l_max=float(life.max()) if n_targets else nan,
        n_detected=n_det,
        n_correct=n_cor,
        n_wrong=n_wrong,
        n_breaks=n_breaks,
        n_targets=n_targets,
        scan_period=T,
        target_id=targets,
        life=life,
        breaks=breaks,
        has_origin=has_origin,
        delay=delay,
    )


def _scan_period(truth: TruthTable, plots: PlotTable | None) -> float:
    """Median ``Δtime / Δscan`` over consecutive distinct scans (0 with fewer than two)."""
    if plots is not None:
        k, t = plots.all_scan_times()
    else:
        k, t = truth.scan, truth.time
    k = np.asarray(k, np.int64)
    k, first = np.unique(k, return_index=True)
    if len(k) < 2:
        return 0.0
    t = np.asarray(t, np.float64)[first]
    return float(np.median(np.diff(t) / np.diff(k)))


def _find(scan_a: np.ndarray, id_a: np.ndarray, scan_b: np.ndarray, id_b: np.ndarray) -> np.ndarray:
    """For each ``(scan, id)`` of ``a``, the row of ``b`` with the same pair, or ``-1``.

    The pairs of ``b`` must be unique.
    """
    scan_a, id_a = np.asarray(scan_a, np.int64), np.asarray(id_a, np.int64)
    scan_b, id_b = np.asarray(scan_b, np.int64), np.asarray(id_b, np.int64)
    if len(scan_a) == 0 or len(scan_b) == 0:
        return np.full(len(scan_a), -1, np.int64)
    s = np.concatenate((scan_a, scan_b))
    i = np.concatenate((id_a, id_b))
    s0, i0 = s.min(), i.min()
    span = i.max() - i0 + 1
    ka, kb = (scan_a - s0) * span + (id_a - i0), (scan_b - s0) * span + (id_b - i0)
    order = np.argsort(kb, kind="stable")
    pos = np.minimum(np.searchsorted(kb[order], ka), len(kb) - 1)
    row = order[pos]
    return np.where(kb[row] == ka, row, -1)


def _association_counts(
    tracks: TrackTable, plots: PlotTable, matching: MOTMatching
) -> tuple[int, int, int]:
    """``(n_detected, n_correct, n_wrong)`` of the Rcc/Rmc definitions."""
    assert plots.origin is not None
    origin = np.asarray(plots.origin, np.int64)
    p_scan = np.asarray(plots.scan, np.int64)
    plot = _check_plot_column(tracks, p_scan)

    # D: distinct (scan, target) pairs with a plot of that target
    det = origin >= 0
    if not det.any():
        return 0, 0, 0
    pairs = np.unique(np.column_stack((p_scan[det], origin[det])), axis=0)

    # per matched pair: the plot its track used at that scan, and that plot's origin
    row = _find(matching.scan, matching.track_id, tracks.scan, tracks.track_id)
    used = np.append(plot, NO_PLOT)[row]  # every matched track is reported: row >= 0
    used_origin = np.append(origin, CLUTTER)[used]
    in_d = _find(matching.scan, matching.target_id, pairs[:, 0], pairs[:, 1]) >= 0
    tgt = np.asarray(matching.target_id, np.int64)
    correct = in_d & (used >= 0) & (used_origin == tgt)
    wrong = in_d & (used >= 0) & (used_origin != tgt)
    return len(pairs), int(np.count_nonzero(correct)), int(np.count_nonzero(wrong))


def _check_plot_column(tracks: TrackTable, p_scan: np.ndarray) -> np.ndarray:
    """The tracks' ``plot`` column as int64, each ``-1`` or a plot row of the same scan."""
    raw = np.asarray(tracks.plot)
    if raw.size and not np.issubdtype(raw.dtype, np.integer):
        f = raw.astype(np.float64)
        if not (np.all(np.isfinite(f)) and np.all(f == np.round(f))):
            raise ValueError("tracks.plot must hold integer plot-table rows (-1 on a miss)")
    plot = raw.astype(np.int64)
    bad = (plot < -1) | (plot >= len(p_scan))
    if bad.any():
        r = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"tracks.plot = {plot[r]} at scan {int(tracks.scan[r])} is not a row of the "
            f"plots table ({len(p_scan)} rows) nor -1"
        )
    used = np.flatnonzero(plot >= 0)
    off = used[p_scan[plot[used]] != np.asarray(tracks.scan, np.int64)[used]]
    if off.size:
        r = int(off[0])
        raise ValueError(
            f"tracks.plot = {plot[r]} at scan {int(tracks.scan[r])} is a plot of scan "
            f"{int(p_scan[plot[r]])}: the tracks were not made from these plots"
        )
    return plot


def _target_walk(
    truth: TruthTable, matching: MOTMatching
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(target ids, order, g, row)``: the truth rows ``order`` sorted by target then scan,
    ``g`` the dense target index of each, ``row`` its pair in ``matching`` (−1: unmatched)."""
    targets, dense = np.unique(np.asarray(truth.target_id, np.int64), return_inverse=True)
    scan = np.asarray(truth.scan, np.int64)
    idx = _find(scan, truth.target_id, matching.scan, matching.target_id)
    order = np.lexsort((scan, dense))
    return targets, order, dense[order], idx[order]


def _confirm_delay(truth: TruthTable, matching: MOTMatching) -> np.ndarray:
    """Per target (ascending id), its live scans before its first match in ``matching``
    (of the online view); NaN if there is none."""
    targets, _, g, row = _target_walk(truth, matching)
    delay = np.full(len(targets), np.nan)
    if len(truth) == 0:
        return delay
    starts = np.flatnonzero(np.r_[True, g[1:] != g[:-1]])
    pos = np.arange(len(g)) - np.repeat(starts, np.diff(np.r_[starts, len(g)]))
    hit = row >= 0
    if hit.any():
        first = np.full(len(targets), np.inf)
        np.minimum.at(first, g[hit], pos[hit].astype(float))
        delay = np.where(np.isfinite(first), first, np.nan)
    return delay


def _continuity(
    truth: TruthTable, matching: MOTMatching, T: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(target ids, breaks per target, life per target in s)`` — Rfg and track life."""
    targets, order, g, row = _target_walk(truth, matching)
    n = len(targets)
    breaks = np.zeros(n, np.int64)
    life = np.zeros(n)
    if len(truth) == 0:
        return targets, breaks, life
    m = row >= 0
    track_id = np.append(np.asarray(matching.track_id, np.int64), -1)
    h = track_id[row]  # -1 (the appended sentinel) where unmatched
    t = np.asarray(truth.time, np.float64)[order]

    same = g[1:] == g[:-1]
    kept = same & m[:-1] & m[1:] & (h[1:] == h[:-1])  # run continues from the previous row
    brk = same & m[:-1] & ~(m[1:] & (h[1:] == h[:-1]))
    np.add.at(breaks, g[1:][brk], 1)

    start = m & ~np.concatenate(([False], kept))
    run = np.cumsum(start) - 1  # run number of each matched row
    n_runs = int(start.sum())
    if n_runs:
        first = t[start]
        last = np.full(n_runs, -np.inf)
        np.maximum.at(last, run[m], t[m])
        np.maximum.at(life, g[start], last - first + T)
    return targets, breaks, life
