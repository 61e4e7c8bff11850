"""One call that scores a tracker's output against the truth with every metric.

:func:`evaluate` aligns tracks and truth — on scan indices when they share their scans, or
at the truth's times (:func:`~mhtrack.metrics.resample.tracks_at_times`) when the tracks
are asynchronous — and runs OSPA, GOSPA, cardinality, CLEAR-MOT, P1 Table 3's association
metrics, OSPA(2) and HOTA; the result is an :class:`~mhtrack.metrics.evaluation.Evaluation`
(its JSON-able dict and plain-text table live there). A reference system's tracks stand
in for the truth through :mod:`~mhtrack.metrics.reference`.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from mhtrack.metrics._common import (
    ScanIndexed,
    check_cutoff,
    check_match_distance,
    check_order,
    check_scans,
    check_tables,
    plot_scans,
    scan_union,
)
from mhtrack.metrics.association import association_indexed
from mhtrack.metrics.cardinality import cardinality_indexed
from mhtrack.metrics.clearmot import clear_mot_indexed
from mhtrack.metrics.evaluation import Evaluation
from mhtrack.metrics.gospa import gospa_indexed
from mhtrack.metrics.hota import hota_indexed
from mhtrack.metrics.identity import DEFAULT_DUBIOUS_DISTANCE, identity_figures
from mhtrack.metrics.ospa import ospa_indexed
from mhtrack.metrics.ospa2 import DEFAULT_OSPA2_WINDOW, check_window, ospa2_indexed
from mhtrack.metrics.resample import (
    DEFAULT_MAX_AGE_S,
    alignment,
    check_max_age,
    is_synchronous,
    tracks_at_times,
    truth_times,
)
from mhtrack.progress import Stages, silent
from mhtrack.records import PlotTable, TrackTable, TruthTable

__all__ = ["Evaluation", "evaluate"]


def evaluate(
    tracks: TrackTable,
    truth: TruthTable,
    *,
    plots: PlotTable | None = None,
    cutoff: float = 500.0,
    order: float = 2.0,
    match_distance: float | None = None,
    scans: npt.ArrayLike | None = None,
    at: str | None = None,
    max_age_s: float = DEFAULT_MAX_AGE_S,
    ospa2_window: int = DEFAULT_OSPA2_WINDOW,
    hota_distance: float | None = None,
    stages: Stages | None = None,
    identity: bool = False,
    update_interval: float | None = None,
    dubious_distance: float = DEFAULT_DUBIOUS_DISTANCE,
) -> Evaluation:
    """Score ``tracks`` against ``truth``: OSPA, GOSPA (α = 2), cardinality, CLEAR-MOT and
    P1 Table 3's Rcc, Rmc, Rfg, Lmin/Lavg/Lmax (:func:`association_metrics`), OSPA(2)
    (:func:`~mhtrack.metrics.ospa2.ospa2_per_scan`, same ``c`` and ``p``) and HOTA
    (:func:`~mhtrack.metrics.hota.hota`); with ``identity`` also the identity figures
    (:func:`~mhtrack.metrics.identity.identity_figures`: ids per aircraft, wrong-code
    rate, ESASSP-style figures).

    **Alignment** (``at``). ``"scans"``: tracks and truth are compared scan by scan; the
    scans evaluated are the sorted union of the truth's scans, the tracks' scans, every
    scan of ``plots`` (empty scans included) and ``scans``; a scan with neither truth nor
    tracks has OSPA = GOSPA = 0 and cardinality error 0. ``"truth-times"``: at each of the
    truth's scans (time ``t``) every track contributes its latest state at or before ``t``
    no older than ``max_age_s``, predicted to ``t`` with constant velocity
    (:func:`~mhtrack.metrics.resample.tracks_at_times`); the scans evaluated are the
    truth's. ``None`` (default): ``"scans"`` when the tables share their scans (every track
    row at a truth scan has that scan's time, plots untimed and agreeing likewise —
    :func:`~mhtrack.metrics.resample.is_synchronous`), else ``"truth-times"``. Means are
    over the scans evaluated.

    Parameters
    ----------
    tracks : TrackTable
        Tracker output.
    truth : TruthTable
        True target states.
    plots : PlotTable, optional
        The run's plots: their scans are evaluated, their scan times give the scan period
        of the track life, and their ``origin`` (when known) with the tracks' ``plot``
        column gives Rcc and Rmc (NaN otherwise).
    cutoff : float, default 500.0
        OSPA/GOSPA cut-off ``c`` (m), finite and ``> 0``.
    order : float, default 2.0
        OSPA/GOSPA order ``p``, finite and ``>= 1``.
    match_distance : float, optional
        CLEAR-MOT matching distance ``d_match`` (m); defaults to ``cutoff``.
    scans : array_like of int, optional
        Extra scan indices (e.g. every scan of the run); ``"scans"`` alignment only.
    at : {"scans", "truth-times"} or None
        The alignment (above); ``None`` chooses it.
    max_age_s : float, default 15.0
        Largest age (s) of a track state used at a truth time, ``>= 0``
        (``"truth-times"`` only).
    ospa2_window : int, default 10
        OSPA(2) window length in scans, ``>= 1``.
    hota_distance : float, optional
        HOTA's ``d_max`` (m): the similarity ``max(0, 1 − d/d_max)`` of a truth–track
        pair falls to 0 at this distance; defaults to ``cutoff``.
    stages : mhtrack.progress.Stages, optional
        Runs each metric as a stage of a progress bar (``evaluate``'s, ``report``'s).
    identity : bool, default False
        Compute :attr:`Evaluation.identity` (off: the result is that of before).
    update_interval, dubious_distance : float
        The probability of update's interval ``T`` (s; default the truth's median time
        step) and the dubious-track threshold (m, default 1 NM); ``identity`` only.

    Returns
    -------
    Evaluation
    """
    tracks, truth = check_tables(tracks, truth)
    c = check_cutoff(cutoff, "cutoff")
    p = check_order(order, "order")
    d_match = (
        c if match_distance is None else check_match_distance(match_distance, "match_distance")
    )
    extra = check_scans(scans)
    p_scans = plot_scans(plots)  # also type-checks plots
    age = check_max_age(max_age_s)
    window = check_window(ospa2_window, "ospa2_window")
    d_max = c if hota_distance is None else check_cutoff(hota_distance, "hota_distance")
    how = alignment(tracks, truth, plots, at)
    raw_tracks, raw_plots = tracks, plots
    n_tracks = len(np.unique(tracks.track_id))
    if how == "scans":
        idx = scan_union(truth.scan, tracks.scan, p_scans, extra)
    else:
        if len(extra):
            raise ValueError("scans applies to at='scans' only (with 'truth-times' the "
                             "truth's scans are evaluated)")
        idx, t_idx = truth_times(truth)
        tracks = tracks_at_times(tracks, t_idx, idx, age)
        if plots is not None and not is_synchronous(tracks, truth, plots):
            plots = None  # frames of timed plots are not the truth's scans: no Rcc/Rmc
    run = stages or silent()
    data = run("index", ScanIndexed.build, tracks, truth, idx)  # checked once, for all
    mot = run("CLEAR-MOT", clear_mot_indexed, data, d_match)
    return Evaluation(
        cutoff=c, order=p, match_distance=d_match, scans=idx,
        ospa=run("OSPA", ospa_indexed, data, c, p),
        gospa=run("GOSPA", gospa_indexed, data, c, p),
        cardinality=run("cardinality", cardinality_indexed, data),
        clear_mot=mot,
        n_tracks=n_tracks,
        n_targets=len(np.unique(truth.target_id)),
        association=run("association", association_indexed, data, plots, mot.matching,
                        d_match),
        at=how,
        max_age_s=None if how == "scans" else age,
        ospa2=run("OSPA(2)", ospa2_indexed, data, c, p, window),
        hota=run("HOTA", hota_indexed, data, d_max),
        identity=identity_figures(raw_tracks, truth, tracks, mot.matching, raw_plots,
                                  update_interval=update_interval,
                                  dubious_distance=dubious_distance,
                                  match_distance=d_match) if identity else None,
    )
