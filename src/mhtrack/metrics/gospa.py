"""GOSPA — the generalised OSPA metric with α = 2.

Rahmathullah, García-Fernández & Svensson (2017), "Generalized optimal sub-pattern
assignment metric", Proc. 20th Int. Conf. Information Fusion (arXiv:1601.05585) — the
GOSPA definition and its assignment form for α = 2, which splits the distance into
localisation, missed-target and false-target costs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mhtrack.metrics import _common
from mhtrack.records import TrackTable, TruthTable


@dataclass(frozen=True, slots=True)
class GOSPAResult:
    """GOSPA distance, its components (metres) and the assignment counts.

    Components are in metres like the distance, with
    ``distance**p == localisation**p + missed**p + false**p``:
    ``localisation = (Σ_assigned d^p)^(1/p)``, ``missed = (c^p/2 · n_missed)^(1/p)``,
    ``false = (c^p/2 · n_false)^(1/p)``.
    """

    distance: float
    localisation: float
    missed: float
    false: float
    n_assigned: int
    n_missed: int
    n_false: int


@dataclass(frozen=True)
class GOSPAPerScan:
    """GOSPA at each scan of ``scan`` (arrays of equal length; see :class:`GOSPAResult`)."""

    scan: np.ndarray
    distance: np.ndarray
    localisation: np.ndarray
    missed: np.ndarray
    false: np.ndarray
    n_assigned: np.ndarray
    n_missed: np.ndarray
    n_false: np.ndarray


def gospa(X: npt.ArrayLike, Y: npt.ArrayLike, c: float, p: float) -> GOSPAResult:
    r"""GOSPA distance (α = 2) of order ``p`` with cut-off ``c`` from truth ``X`` to estimate ``Y``.

    .. math::
        d_p^{(c,2)}(X, Y) = \Big(\min_{\gamma\in\Gamma} \sum_{(i,j)\in\gamma} d(x_i, y_j)^p
            + \frac{c^p}{2}\big(|X| + |Y| - 2|\gamma|\big)\Big)^{1/p}

    where ``Γ`` is the set of partial assignments between ``X`` and ``Y`` whose pairs are
    all closer than ``c`` (Rahmathullah, García-Fernández & Svensson 2017, assignment form
    for α = 2). Unassigned truths are *missed* (``n_missed = |X| − |γ|``), unassigned
    estimates *false* (``n_false = |Y| − |γ|``). Solved with
    :func:`scipy.optimize.linear_sum_assignment` on ``min(d, c)^p``; a pair at distance
    ``>= c`` costs the same assigned (``c^p``) as left as one miss plus one false
    (``2 · c^p/2``) and is reported as the latter. Unlike OSPA there is no normalisation:
    GOSPA grows with the number of targets. Both sets empty: all zero.

    Parameters
    ----------
    X : (m, 2) array_like
        True positions (metres).
    Y : (n, 2) array_like
        Estimated positions (metres).
    c, p : float
        Cut-off distance (finite, ``> 0``) and order (finite, ``>= 1``).

    Returns
    -------
    GOSPAResult
    """
    return _gospa(*_common.checked_sets(X, Y, c, p))


def _gospa(X: np.ndarray, Y: np.ndarray, c: float, p: float) -> GOSPAResult:
    m, n = len(X), len(Y)
    d = _common.assigned_distances(X, Y, c, p)
    d = d[d < c]
    n_assigned = len(d)
    n_missed, n_false = m - n_assigned, n - n_assigned
    loc_u = float(np.sum((d / c) ** p))  # in units of c^p
    inv = 1.0 / p
    return GOSPAResult(
        distance=c * (loc_u + 0.5 * (n_missed + n_false)) ** inv,
        localisation=c * loc_u**inv,
        missed=c * (0.5 * n_missed) ** inv,
        false=c * (0.5 * n_false) ** inv,
        n_assigned=n_assigned,
        n_missed=n_missed,
        n_false=n_false,
    )


def gospa_per_scan(
    tracks: TrackTable,
    truth: TruthTable,
    c: float,
    p: float,
    *,
    scans: npt.ArrayLike | None = None,
) -> GOSPAPerScan:
    """GOSPA (α = 2) from the truth's to the tracks' positions at every scan.

    The parameters and the scans evaluated are :func:`~mhtrack.metrics.ospa.ospa_per_scan`'s;
    a scan with neither truth nor tracks has GOSPA 0. See :func:`gospa`."""
    return gospa_indexed(*_common.checked_distance_input(tracks, truth, c, p, scans))


def gospa_indexed(data: _common.ScanIndexed, c: float, p: float) -> GOSPAPerScan:
    """:func:`gospa_per_scan` on checked, scan-indexed tables and checked ``c``, ``p``."""
    results = [_gospa(X, Y, c, p) for X, Y in data.points()]
    return _common.per_scan(GOSPAPerScan, GOSPAResult, data.scans, results)
