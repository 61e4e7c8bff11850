"""Cardinality per scan: number of reported tracks against number of true targets.

The cardinality error at scan ``k`` is ``|n̂_k − n_k|`` with ``n̂_k`` the number of track
rows and ``n_k`` the number of truth rows at that scan (``docs/metrics.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mhtrack.metrics._common import ScanIndexed, all_scans, check_tables
from mhtrack.records import TrackTable, TruthTable


@dataclass(frozen=True)
class CardinalityPerScan:
    """Counts at each scan of ``scan``: ``n_tracks`` (n̂), ``n_true`` (n) and
    ``error = |n̂ − n|`` (all int64 arrays of equal length)."""

    scan: np.ndarray
    n_tracks: np.ndarray
    n_true: np.ndarray
    error: np.ndarray


def cardinality_per_scan(
    tracks: TrackTable, truth: TruthTable, *, scans: npt.ArrayLike | None = None
) -> CardinalityPerScan:
    """Number of tracks ``n̂_k``, of true targets ``n_k`` and the error ``|n̂_k − n_k|``.

    Scans are the sorted union of ``truth.scan``, ``tracks.scan`` and ``scans``.

    Parameters
    ----------
    tracks : TrackTable
    truth : TruthTable
    scans : array_like of int, optional
        Extra scan indices to evaluate (their counts are zero when absent from both).

    Returns
    -------
    CardinalityPerScan
    """
    tracks, truth = check_tables(tracks, truth)
    return cardinality_indexed(ScanIndexed.build(tracks, truth,
                                                 all_scans(tracks, truth, scans)))


def cardinality_indexed(data: ScanIndexed) -> CardinalityPerScan:
    """:func:`cardinality_per_scan` on checked, scan-indexed tables."""
    n_hat = data.track_rows.counts.astype(np.int64)
    n = data.truth_rows.counts.astype(np.int64)
    return CardinalityPerScan(scan=data.scans, n_tracks=n_hat, n_true=n,
                              error=np.abs(n_hat - n))
