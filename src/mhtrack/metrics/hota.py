"""HOTA — Higher Order Tracking Accuracy, for point targets.

Luiten, Ošep, Dendorfer, Torr, Geiger, Leal-Taixé & Leibe (2021), "HOTA: A higher order
metric for evaluating multi-object tracking", Int. J. Computer Vision 129:548–578 — the
definitions of HOTA, DetA, AssA, LocA (§5) and of the matching (§6). The reference code is
``trackeval`` (``trackeval.metrics.HOTA``); this module follows its matching and its
conventions for empty inputs, and the suite checks it against it to 1e-6.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mhtrack.metrics._common import (
    ScanIndexed,
    all_scans,
    check_cutoff,
    check_tables,
    pairwise_distance,
)
from mhtrack.records import TrackTable, TruthTable

#: The localisation thresholds ``α = 0.05, 0.10, …, 0.95`` (Luiten et al. 2021, eq. 1:
#: HOTA is averaged over them), computed as ``trackeval`` does.
ALPHAS = np.arange(0.05, 0.99, 0.05)
_EPS = float(np.finfo(float).eps)
#: The keys of :meth:`HOTAResult.summary` (and of ``Evaluation.to_dict``).
HOTA_KEYS = ("hota", "deta", "assa", "loca", "hota_distance")


@dataclass(frozen=True)
class HOTAResult:
    """HOTA and its parts (each in [0, 1], higher is better).

    ``hota, deta, assa, loca, detre, detpr, assre, asspr`` are the means over
    :data:`ALPHAS`; the ``*_alpha`` arrays hold the value at each ``α``. ``d_max`` (m) is
    the distance at which the similarity falls to 0; ``tp, fn, fp`` the counts per ``α``.
    """

    d_max: float
    alpha: np.ndarray
    hota_alpha: np.ndarray
    deta_alpha: np.ndarray
    assa_alpha: np.ndarray
    loca_alpha: np.ndarray
    detre_alpha: np.ndarray
    detpr_alpha: np.ndarray
    assre_alpha: np.ndarray
    asspr_alpha: np.ndarray
    tp: np.ndarray
    fn: np.ndarray
    fp: np.ndarray

    @property
    def hota(self) -> float:
        return float(np.mean(self.hota_alpha))

    @property
    def deta(self) -> float:
        return float(np.mean(self.deta_alpha))

    @property
    def assa(self) -> float:
        return float(np.mean(self.assa_alpha))

    @property
    def loca(self) -> float:
        return float(np.mean(self.loca_alpha))

    def summary(self) -> dict[str, float]:
        """``{hota, deta, assa, loca, hota_distance}``: the means over ``α`` and ``d_max``."""
        return dict(zip(HOTA_KEYS, (self.hota, self.deta, self.assa, self.loca, self.d_max),
                        strict=True))

    @property
    def detre(self) -> float:
        return float(np.mean(self.detre_alpha))

    @property
    def detpr(self) -> float:
        return float(np.mean(self.detpr_alpha))

    @property
    def assre(self) -> float:
        return float(np.mean(self.assre_alpha))

    @property
    def asspr(self) -> float:
        return float(np.mean(self.asspr_alpha))


def similarity(d: np.ndarray, d_max: float) -> np.ndarray:
    """Point-target similarity ``S = max(0, 1 − d/d_max)``: 1 at the same position, 0 at
    ``d_max`` or farther (the localisation score that replaces HOTA's IoU)."""
    return np.maximum(0.0, 1.0 - d / d_max)


def hota(tracks: TrackTable, truth: TruthTable, d_max: float, *,
         scans: npt.ArrayLike | None = None) -> HOTAResult:
    r"""HOTA of ``tracks`` against ``truth`` with similarity ``S = max(0, 1 − d/d_max)``.

    Per ``α`` (Luiten et al. 2021, §5): a truth–track pair at one scan is a true positive
    (TP) when matched with ``S ≥ α``; unmatched truths are FN, unmatched tracks FP.

    .. math::
        \mathrm{DetA}_α = \frac{|TP|}{|TP| + |FN| + |FP|},\quad
        \mathrm{AssA}_α = \frac{1}{|TP|}\sum_{c∈TP}
            \frac{|TPA(c)|}{|TPA(c)| + |FNA(c)| + |FPA(c)|},\quad
        \mathrm{HOTA}_α = \sqrt{\mathrm{DetA}_α\,\mathrm{AssA}_α},

    ``LocA_α`` the mean ``S`` of the TPs, and HOTA = the mean of ``HOTA_α`` over
    :data:`ALPHAS` (likewise DetA, AssA, LocA). Matching (§6, as ``trackeval``): at each
    scan one Hungarian assignment maximising ``Σ A(i, j) S(i, j)`` where ``A`` is the
    global alignment of the two identities over the whole run,
    ``A = Σ_t S̃ / (n_gt + n_trk − Σ_t S̃)`` with ``S̃ = S/(row sum + column sum − S)``;
    for each ``α`` the pairs with ``S ≥ α`` are the TPs.

    Parameters
    ----------
    tracks, truth : TrackTable, TruthTable
    d_max : float
        Distance (m, ``> 0``) at which the similarity reaches 0.
    scans : array_like of int, optional
        Extra scan indices (they add nothing unless they hold rows).
    """
    tracks, truth = check_tables(tracks, truth)
    d = check_cutoff(d_max, "d_max")
    return hota_indexed(ScanIndexed.build(tracks, truth, all_scans(tracks, truth, scans)), d)


def hota_indexed(data: ScanIndexed, d_max: float) -> HOTAResult:
    """:func:`hota` on checked, scan-indexed tables and a checked ``d_max``."""
    from scipy.optimize import linear_sum_assignment
    na = len(ALPHAS)
    tp, fn, fp = np.zeros(na), np.zeros(na), np.zeros(na)
    loc = np.zeros(na)
    gt_uniq = np.unique(data.truth.target_id)
    tr_uniq = np.unique(data.tracks.track_id)
    frames = []  # (gt idx, track idx, S) per scan
    for k, (X, Y) in enumerate(data.points()):
        g = np.searchsorted(gt_uniq, data.truth.target_id[data.truth_rows.rows(k)])
        t = np.searchsorted(tr_uniq, data.tracks.track_id[data.track_rows.rows(k)])
        frames.append((g, t, similarity(pairwise_distance(X, Y), d_max)))
    n_gt_dets, n_tr_dets = len(data.truth), len(data.tracks)
    if n_tr_dets == 0 or n_gt_dets == 0:  # trackeval's early returns
        (fn if n_tr_dets == 0 else fp)[:] = n_gt_dets if n_tr_dets == 0 else n_tr_dets
        z = np.zeros(na)
        return HOTAResult(d_max, ALPHAS, z, z, z, np.ones(na), z, z, z, z, tp, fn, fp)
    G, T = len(gt_uniq), len(tr_uniq)
    potential = np.zeros((G, T))
    gt_count = np.zeros((G, 1))
    tr_count = np.zeros((1, T))
    for g, t, S in frames:
        denom = S.sum(0)[None, :] + S.sum(1)[:, None] - S
        s_iou = np.zeros_like(S)
        ok = denom > _EPS
        s_iou[ok] = S[ok] / denom[ok]
        potential[g[:, None], t[None, :]] += s_iou
        gt_count[g] += 1
        tr_count[0, t] += 1
    align = potential / (gt_count + tr_count - potential)
    matches = np.zeros((na, G, T))
    for g, t, S in frames:
        if len(g) == 0 or len(t) == 0:
            fp += len(t)
            fn += len(g)
            continue
        r, c = linear_sum_assignment(-(align[g[:, None], t[None, :]] * S))
        s = S[r, c]
        for a, alpha in enumerate(ALPHAS):
            ok = s >= alpha - _EPS
            n_ok = int(ok.sum())
            tp[a] += n_ok
            fn[a] += len(g) - n_ok
            fp[a] += len(t) - n_ok
            if n_ok:
                loc[a] += s[ok].sum()
                matches[a, g[r[ok]], t[c[ok]]] += 1
    den = gt_count[None] + tr_count[None] - matches  # (na, G, T)
    tp1 = np.maximum(1.0, tp)
    assa = np.sum(matches * matches / np.maximum(1.0, den), axis=(1, 2)) / tp1
    assre = np.sum(matches * matches / np.maximum(1.0, gt_count[None]), axis=(1, 2)) / tp1
    asspr = np.sum(matches * matches / np.maximum(1.0, tr_count[None]), axis=(1, 2)) / tp1
    loca = np.maximum(1e-10, loc) / np.maximum(1e-10, tp)
    deta = tp / np.maximum(1.0, tp + fn + fp)
    detre = tp / np.maximum(1.0, tp + fn)
    detpr = tp / np.maximum(1.0, tp + fp)
    return HOTAResult(d_max, ALPHAS, np.sqrt(deta * assa), deta, assa, loca, detre, detpr,
                      assre, asspr, tp, fn, fp)
