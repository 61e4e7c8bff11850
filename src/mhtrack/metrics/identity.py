"""Identity figures of one run (issue 29 item 7): ids per aircraft, the wrong-code /
wrong-address association rate, and figures in the manner of the EUROCONTROL
Specification for ATM Surveillance System Performance (ESASSP, EUROCONTROL-SPEC-0147,
vol. 1, ed. 1.1, 2015): horizontal RMS position error, probability of update, extra
tracks and dubious tracks.

ESASSP states these as requirements on a surveillance chain measured against a
reference trajectory; the operational definitions below (which pairs, which interval,
which threshold) are ours, written so that each figure is computable by hand from the
truth, the tracks and the CLEAR-MOT matching (:mod:`mhtrack.metrics.clearmot`). ESASSP's
own text could not be read here (stored copies hold its front matter only); they were
compared instead with OpenATS COMPASS's evaluation requirements (its user manual:
Detection, Position Distance RMS, Identification False, Extra Track, Dubious Tracks) —
docs/metrics.md, *Identity figures*, gives the comparison; the multiple/false split of
the extra tracks follows COMPASS's Extra Track, and our dubious rate is a gross-error
rate, not COMPASS's test-data-only dubious track.

**Dominant target** of a track: the target it is matched to at most evaluated scans
(ties: the smaller target id); a track never matched has none (a false track).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mhtrack.metrics.clearmot import MOTMatching
from mhtrack.records import PlotTable, TrackTable, TruthTable

#: ESASSP's dubious-track figure is about gross horizontal errors; our default threshold
#: is one nautical mile (m).
DEFAULT_DUBIOUS_DISTANCE = 1852.0
#: The keys :meth:`IdentityFigures.to_dict` writes.
IDENTITY_KEYS = ("ids_per_aircraft", "wrong_code_rate", "n_code_rows", "rms_horizontal",
                 "p_update", "update_interval", "extra_track_rate", "multiple_track_rate",
                 "false_track_rate", "dubious_track_rate", "dubious_distance")


@dataclass(frozen=True)
class IdentityFigures:
    """The figures of :func:`identity_figures` (NaN where undefined)."""

    ids_per_aircraft: float
    wrong_code_rate: float
    n_code_rows: int
    rms_horizontal: float
    p_update: float
    update_interval: float
    extra_track_rate: float
    multiple_track_rate: float
    false_track_rate: float
    dubious_track_rate: float
    dubious_distance: float

    def to_dict(self) -> dict[str, float | int]:
        return {k: getattr(self, k) for k in IDENTITY_KEYS}


def dominant_targets(matching: MOTMatching) -> dict[int, int]:
    """Track id → its dominant target (module docstring)."""
    out: dict[int, int] = {}
    if not len(matching):
        return out
    pairs, counts = np.unique(np.column_stack((matching.track_id, matching.target_id)),
                              axis=0, return_counts=True)
    best: dict[int, int] = {}
    # rows sorted by (track, target): a strictly larger count wins, so ties keep the
    # smaller target id
    for (trk, tgt), n in zip(pairs.tolist(), counts.tolist(), strict=True):
        if n > best.get(trk, 0):
            out[trk], best[trk] = tgt, n
    return out


def target_identities(plots: PlotTable) -> dict[int, tuple[int, int]]:
    """Target id → ``(Mode 3/A code, Mode S address)`` of the truth target: the most
    frequent non-garbled (G = 0) code and the most frequent address among the plots whose
    ``origin`` is that target (ties: the smaller value; ``-1`` when none); empty without
    ``origin`` or attributes."""
    a, origin = plots.attrs, plots.origin
    if a is None or origin is None:
        return {}
    o = np.asarray(origin)
    rows = o >= 0
    code = np.where(a.mode_3a_g == 0, a.mode_3a, -1)  # a garbled code is not counted
    codes, addresses = _modes(o[rows], code[rows]), _modes(o[rows], a.address[rows])
    return {int(t): (codes.get(int(t), -1), addresses.get(int(t), -1))
            for t in np.unique(o[rows]).tolist()}


def _modes(key: np.ndarray, v: np.ndarray) -> dict[int, int]:
    """Key → the most frequent of its values ``>= 0`` (ties: the smaller value; keys
    without one left out), for all keys at once."""
    ok = v >= 0
    if not ok.any():
        return {}
    pairs, counts = np.unique(np.column_stack((key[ok], v[ok])), axis=0,
                              return_counts=True)
    order = np.lexsort((pairs[:, 1], -counts, pairs[:, 0]))  # per key: most, then smallest
    first = order[np.r_[True, np.diff(pairs[order, 0]) != 0]]
    return dict(zip(pairs[first, 0].tolist(), pairs[first, 1].tolist(), strict=True))


def _groups(keys: np.ndarray) -> list[tuple[int, np.ndarray]]:
    """``(key, positions)`` for each distinct key in increasing order, the positions in
    increasing order (one stable sort: the grouping every per-target figure here uses,
    instead of masking all rows once per target)."""
    keys = np.asarray(keys)
    order = np.argsort(keys, kind="stable")
    cuts = np.flatnonzero(np.diff(keys[order])) + 1
    return [(int(keys[g[0]]), g) for g in np.split(order, cuts)] if keys.size else []


def identity_figures(tracks: TrackTable, truth: TruthTable, aligned: TrackTable,
                     matching: MOTMatching, plots: PlotTable | None = None, *,
                     update_interval: float | None = None,
                     dubious_distance: float = DEFAULT_DUBIOUS_DISTANCE,
                     match_distance: float | None = None) -> IdentityFigures:
    """The identity figures of ``tracks`` (the tracker's rows, ``plot`` indexing
    ``plots``) against ``truth``, given the tracks ``aligned`` with the truth's scans
    and their CLEAR-MOT ``matching`` (:func:`~mhtrack.metrics.evaluate.evaluate`).

    * **ids per aircraft**: mean, over the targets matched at least once, of the number
      of distinct track ids matched to the target (1 is ideal; issue 29).
    * **wrong-code rate**: among the tracks' rows that used a plot (``plot >= 0``) of a
      track with a dominant target, whose plot carries a non-garbled Mode 3/A code or a
      Mode S address that the target also has (:func:`target_identities`; ``n_code_rows``
      of them), the share whose plot's code or address differs from the target's. NaN
      without plots with attributes and ``origin``.
    * **horizontal RMS position error** (ESASSP's horizontal position RMS error):
      ``sqrt(mean d²)`` over the matched pairs (m).
    * **probability of update** (ESASSP's probability of update at a given update
      interval): each target's life ``[t_first, t_last]`` in the truth is cut into
      ``ceil((t_last − t_first) / T)`` intervals ``[t_first + jT, t_first + (j+1)T)`` (at
      least one; the last also holds ``t_last``); an interval is updated when a row of the
      tracker with a plot (``plot >= 0``) of a track whose dominant target it is falls in
      it. ``P = updated / intervals`` over all targets. ``T`` (``update_interval``)
      defaults to the data's own update interval: the median of the positive time steps
      between successive plots of one target (all sensors together) when ``plots`` have
      ``origin``, else the truth's median time step.
    * **extra-track rate**: the share of the aligned track states not matched to any
      target; of them, the **multiple-track rate** (a second track on a target: the
      nearest target present at the state's scan lies within ``match_distance``,
      default ``dubious_distance``, and is matched to another track there — OpenATS
      COMPASS's "extra track", an update of a target that has more than one track) and
      the **false-track rate** (no target within ``match_distance`` at that scan: a
      false track, or a track grossly off its target), both over all aligned states;
      their sum is the extra-track rate.
    * **dubious-track rate** (ESASSP's dubious tracks, gross horizontal errors): the share
      of tracks with a dominant target of which some aligned state lies farther than
      ``dubious_distance`` from that target at a scan where the target is present.
    """
    dom = dominant_targets(matching)
    tgt, trk = np.asarray(matching.target_id), np.asarray(matching.track_id)
    pairs = np.unique(np.column_stack((tgt, trk)), axis=0) if len(tgt) else np.empty((0, 2))
    n_ids = np.unique(pairs[:, 0], return_counts=True)[1]  # distinct tracks per target
    d = np.asarray(matching.distance, float)
    rate, n_code = _wrong_code(tracks, plots, dom)
    T = _default_interval(truth, plots) if update_interval is None else float(update_interval)
    n_states = len(aligned)
    return IdentityFigures(
        ids_per_aircraft=float(np.mean(n_ids)) if n_ids.size else float("nan"),
        wrong_code_rate=rate, n_code_rows=n_code,
        rms_horizontal=float(np.sqrt(np.mean(d**2))) if d.size else float("nan"),
        p_update=_p_update(tracks, truth, dom, T), update_interval=T,
        extra_track_rate=(n_states - len(matching)) / n_states if n_states else float("nan"),
        **_extra_kinds(aligned, truth, matching, dubious_distance if match_distance is None
                       else float(match_distance)),
        dubious_track_rate=_dubious(aligned, truth, dom, dubious_distance),
        dubious_distance=float(dubious_distance))


def _wrong_code(tracks: TrackTable, plots: PlotTable | None, dom: dict[int, int]
                ) -> tuple[float, int]:
    ident = {} if plots is None else target_identities(plots)
    if not ident or plots is None or plots.attrs is None:
        return float("nan"), 0
    a = plots.attrs
    plot = np.asarray(tracks.plot, np.int64)
    target = np.array([dom.get(int(k), -1) for k in tracks.track_id.tolist()], np.int64)
    code_t = np.array([ident.get(int(t), (-1, -1))[0] for t in target.tolist()], np.int64)
    addr_t = np.array([ident.get(int(t), (-1, -1))[1] for t in target.tolist()], np.int64)
    used = (plot >= 0) & (target >= 0)
    p = np.where(used, plot, 0)
    code_p = np.where(a.mode_3a_g[p] == 0, a.mode_3a[p], -1)
    addr_p = a.address[p]
    has_code, has_addr = (code_p >= 0) & (code_t >= 0), (addr_p >= 0) & (addr_t >= 0)
    rows = used & (has_code | has_addr)
    wrong = rows & ((has_code & (code_p != code_t)) | (has_addr & (addr_p != addr_t)))
    n = int(np.count_nonzero(rows))
    return (np.count_nonzero(wrong) / n if n else float("nan")), n


def _default_interval(truth: TruthTable, plots: PlotTable | None) -> float:
    if plots is not None and plots.origin is not None and (plots.origin >= 0).any():
        o, t = np.asarray(plots.origin), np.asarray(plots.time, float)
        o, t = o[o >= 0], t[o >= 0]
        order = np.lexsort((t, o))  # by target, then time
        o, t = o[order], t[order]
        steps = np.diff(t)[np.diff(o) == 0]  # successive plots of one target
    else:
        steps = np.diff(np.unique(np.asarray(truth.time, float)))
    steps = steps[steps > 0]
    return float(np.median(steps)) if steps.size else float("nan")


def _p_update(tracks: TrackTable, truth: TruthTable, dom: dict[int, int], T: float) -> float:
    if not (np.isfinite(T) and T > 0) or not len(truth):
        return float("nan")
    target = np.array([dom.get(int(k), -1) for k in tracks.track_id.tolist()], np.int64)
    tt = np.asarray(truth.time, float)
    ids, first, last = [], [], []
    for tid, g in _groups(truth.target_id):
        ids.append(tid)
        first.append(tt[g].min())
        last.append(tt[g].max())
    ids_a, t0, t1 = np.array(ids, np.int64), np.array(first), np.array(last)
    n = np.maximum(1, np.ceil((t1 - t0) / T).astype(np.int64))  # intervals per target
    # each updating row's target among the truth's (rows of other targets count nowhere)
    k = np.searchsorted(ids_a, target)
    k = np.minimum(k, len(ids_a) - 1)
    upd = (np.asarray(tracks.plot) >= 0) & (target >= 0) & (ids_a[k] == target)
    tu, k = np.asarray(tracks.time, float)[upd], k[upd]
    inside = (tu >= t0[k]) & (tu <= t1[k])
    tu, k = tu[inside], k[inside]
    j = np.minimum(np.floor((tu - t0[k]) / T).astype(np.int64), n[k] - 1)
    updated = len(np.unique(np.column_stack((k, j)), axis=0)) if k.size else 0
    return updated / int(n.sum())


def _extra_kinds(aligned: TrackTable, truth: TruthTable, matching: MOTMatching,
                 limit: float) -> dict[str, float]:
    """``multiple_track_rate`` and ``false_track_rate`` (:func:`identity_figures`)."""
    n = len(aligned)
    if not n:
        return {"multiple_track_rate": float("nan"), "false_track_rate": float("nan")}
    matched = {(int(s), int(k)) for s, k in zip(matching.scan.tolist(),
                                                 matching.track_id.tolist(), strict=True)}
    target_of = {(int(s), int(t)): int(k) for s, t, k in zip(
        matching.scan.tolist(), matching.target_id.tolist(), matching.track_id.tolist(),
        strict=True)}
    ts, tt = np.asarray(truth.scan), np.asarray(truth.target_id)
    at_scan = dict(_groups(ts))  # scan -> truth rows at it
    none = np.empty(0, np.int64)
    multiple = false = 0
    for i, (s, k) in enumerate(zip(aligned.scan.tolist(), aligned.track_id.tolist(),
                                   strict=True)):
        if (int(s), int(k)) in matched:
            continue
        here = at_scan.get(int(s), none)
        d = np.hypot(truth.x[here] - aligned.x[i], truth.y[here] - aligned.y[i])
        if not here.size or d.min() > limit:
            false += 1
            continue
        other = target_of.get((int(s), int(tt[here[np.argmin(d)]])))
        multiple += other is not None and other != int(k)
    return {"multiple_track_rate": multiple / n, "false_track_rate": false / n}


def _dubious(aligned: TrackTable, truth: TruthTable, dom: dict[int, int],
             limit: float) -> float:
    if not dom:
        return float("nan")
    where = {(int(s), int(t)): i for i, (s, t) in enumerate(zip(
        truth.scan.tolist(), truth.target_id.tolist(), strict=True))}
    bad = set()
    for i, (s, k) in enumerate(zip(aligned.scan.tolist(), aligned.track_id.tolist(),
                                   strict=True)):
        j = where.get((int(s), dom.get(int(k), -1)))
        if j is not None and np.hypot(aligned.x[i] - truth.x[j],
                                      aligned.y[i] - truth.y[j]) > limit:
            bad.add(int(k))
    return len(bad) / len(dom)
