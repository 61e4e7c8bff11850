"""OSPA — the optimal sub-pattern assignment metric between two finite point sets.

Schuhmacher, Vo & Vo (2008), "A consistent metric for performance evaluation of
multi-object filters", IEEE Trans. Signal Process. 56(8):3447–3457 — the definition of
the OSPA metric and its split into localisation and cardinality errors.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mhtrack.metrics._common import (
    ScanIndexed,
    assigned_distances,
    checked_distance_input,
    checked_sets,
    per_scan,
)
from mhtrack.records import TrackTable, TruthTable


@dataclass(frozen=True, slots=True)
class OSPAResult:
    """OSPA distance and its two components (metres).

    ``distance**p == localisation**p + cardinality**p``.
    """

    distance: float
    localisation: float
    cardinality: float


@dataclass(frozen=True)
class OSPAPerScan:
    """OSPA at each scan of ``scan`` (arrays of equal length)."""

    scan: np.ndarray
    distance: np.ndarray
    localisation: np.ndarray
    cardinality: np.ndarray


def ospa(X: npt.ArrayLike, Y: npt.ArrayLike, c: float, p: float) -> OSPAResult:
    r"""OSPA distance of order ``p`` with cut-off ``c`` between point sets ``X`` and ``Y``.

    For ``X`` with ``m`` points and ``Y`` with ``n`` points, ``m <= n`` (swap otherwise;
    the metric is symmetric), and ``d^(c)(x, y) = min(c, ‖x − y‖)``:

    .. math::
        \bar d_p^{(c)}(X, Y) = \Big(\frac{1}{n}\big(\min_{\pi\in\Pi_n}
            \sum_{i=1}^{m} d^{(c)}(x_i, y_{\pi(i)})^p + c^p (n - m)\big)\Big)^{1/p}

    (Schuhmacher, Vo & Vo 2008, definition of OSPA). Components (same paper):
    localisation ``(1/n · min_π Σ d^(c)(x_i, y_π(i))^p)^(1/p)`` — pairs farther than
    ``c`` count as ``c`` here — and cardinality ``(c^p (n − m)/n)^(1/p)``.
    Both sets empty: all zero. One set empty: distance ``c`` (all cardinality).
    The assignment ``π`` is found by :func:`scipy.optimize.linear_sum_assignment` on
    ``min(d, c)^p``.

    Parameters
    ----------
    X, Y : (m, 2), (n, 2) array_like
        Point positions (metres); either may be empty.
    c : float
        Cut-off distance, finite and ``> 0``.
    p : float
        Order, finite and ``>= 1``.

    Returns
    -------
    OSPAResult
    """
    return _ospa(*checked_sets(X, Y, c, p))


def _ospa(X: np.ndarray, Y: np.ndarray, c: float, p: float) -> OSPAResult:
    m, n = len(X), len(Y)
    big = max(m, n)
    if big == 0:
        return OSPAResult(0.0, 0.0, 0.0)
    d = assigned_distances(X, Y, c, p)
    loc_u = float(np.sum((np.minimum(d, c) / c) ** p))  # Σ d^(c)^p / c^p
    card_u = float(abs(m - n))  # c^p |n − m| / c^p
    return OSPAResult(
        distance=c * ((loc_u + card_u) / big) ** (1.0 / p),
        localisation=c * (loc_u / big) ** (1.0 / p),
        cardinality=c * (card_u / big) ** (1.0 / p),
    )


def ospa_per_scan(
    tracks: TrackTable,
    truth: TruthTable,
    c: float,
    p: float,
    *,
    scans: npt.ArrayLike | None = None,
) -> OSPAPerScan:
    """OSPA between the truth's and the tracks' positions at every scan.

    Scans are the sorted union of ``truth.scan``, ``tracks.scan`` and ``scans`` (pass all
    scan indices of the run so that scans where both sets are empty — OSPA 0 — and scans
    with truth but no track — OSPA ``c`` — are all counted). See :func:`ospa`.

    Parameters
    ----------
    tracks : TrackTable
    truth : TruthTable
    c, p : float
        Cut-off (``> 0``, metres) and order (``>= 1``).
    scans : array_like of int, optional
        Extra scan indices to evaluate.

    Returns
    -------
    OSPAPerScan
    """
    return ospa_indexed(*checked_distance_input(tracks, truth, c, p, scans))


def ospa_indexed(data: ScanIndexed, c: float, p: float) -> OSPAPerScan:
    """:func:`ospa_per_scan` on checked, scan-indexed tables and checked ``c``, ``p``."""
    results = [_ospa(X, Y, c, p) for X, Y in data.points()]
    return per_scan(OSPAPerScan, OSPAResult, data.scans, results)
