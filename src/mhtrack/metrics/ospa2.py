"""OSPA(2) — the OSPA metric between sets of tracks over a sliding time window.

Beard, Vo & Vo (2017), "OSPA(2): Using the OSPA metric to evaluate multi-target tracking
performance", Proc. Int. Conf. Control, Automation and Information Sciences (ICCAIS),
pp. 86–91; also Beard, Vo & Vo (2020), "A solution for large-scale multi-object
tracking", IEEE Trans. Signal Process. 68:2754–2769, §VI-A. MATLAB's
``trackOSPAMetric`` (``Metric="OSPA(2)"``) computes the same quantity.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mhtrack.metrics._common import ScanIndex, ScanIndexed, checked_distance_input
from mhtrack.records import TrackTable, TruthTable

#: Default window length ``w`` (scans): OSPA(2) at scan ``k`` compares the tracks over the
#: evaluated scans ``k − w < s ≤ k``. Our choice: ten scans is long enough for identity
#: swaps and breaks to count, short enough to show when they happen.
DEFAULT_OSPA2_WINDOW = 10


@dataclass(frozen=True)
class OSPA2PerScan:
    """OSPA(2) at each scan of ``scan`` over the window ending there (arrays of equal
    length; metres). ``distance**p == localisation**p + cardinality**p``; ``window`` is
    the window length in scans."""

    scan: np.ndarray
    distance: np.ndarray
    localisation: np.ndarray
    cardinality: np.ndarray
    window: int


def check_window(value: int, name: str = "window") -> int:
    """A window length: an integer ``>= 1`` (scans)."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
        raise ValueError(f"{name} must be an integer >= 1 (scans), got {value!r}")
    return int(value)


def ospa2_per_scan(
    tracks: TrackTable,
    truth: TruthTable,
    c: float,
    p: float,
    window: int = DEFAULT_OSPA2_WINDOW,
    *,
    scans: npt.ArrayLike | None = None,
) -> OSPA2PerScan:
    r"""OSPA(2) of order ``p`` and cut-off ``c`` over a window of ``window`` scans.

    At each evaluated scan ``k`` (the sorted union of the tables' scans and ``scans``, as
    :func:`~mhtrack.metrics.ospa.ospa_per_scan`) the window ``W`` holds the evaluated scans
    ``s`` with ``k − window < s ≤ k``. Each track (truth target) with at least one state in
    ``W`` is a function ``x`` on its domain ``D_x ⊆ W``. The base distance between a truth
    ``x`` and a track ``y`` is their time-averaged per-scan OSPA (Beard, Vo & Vo 2017):

    .. math::
        \tilde d^{(c)}(x, y) = \frac{1}{|D_x ∪ D_y|} \sum_{t ∈ D_x ∪ D_y}
            d^{(c)}(x(t), y(t)),\quad
        d^{(c)} = \begin{cases} \min(c, ‖x(t) − y(t)‖) & t ∈ D_x ∩ D_y \\
                                c & \text{otherwise (one state missing)} \end{cases}

    and OSPA(2) is the OSPA of order ``p`` with cut-off ``c`` (``\tilde d ≤ c``) between
    the two sets of tracks under this base distance (:func:`~mhtrack.metrics.ospa.ospa`),
    with the same localisation/cardinality split. With ``window = 1`` it is the OSPA of
    each scan. Neither set with a state in ``W``: 0.

    Parameters
    ----------
    tracks, truth : TrackTable, TruthTable
    c, p : float
        Cut-off (``> 0``, metres) and order (``>= 1``).
    window : int, default :data:`DEFAULT_OSPA2_WINDOW`
        Window length ``w`` in scans, ``>= 1``.
    scans : array_like of int, optional
        Extra scan indices to evaluate.

    Returns
    -------
    OSPA2PerScan
    """
    w = check_window(window)
    return ospa2_indexed(*checked_distance_input(tracks, truth, c, p, scans), w)


def ospa2_indexed(data: ScanIndexed, c: float, p: float, window: int) -> OSPA2PerScan:
    """:func:`ospa2_per_scan` on checked, scan-indexed tables and checked ``c, p, window``."""
    scans = data.scans
    lo = np.searchsorted(scans, scans - window, side="right")
    out = np.zeros((3, len(scans)))
    for k in range(len(scans)):
        out[:, k] = _window_ospa2(data, int(lo[k]), k + 1, c, p)
    return OSPA2PerScan(scans, out[0], out[1], out[2], window)


def _window_states(rows_of: ScanIndex, ids: np.ndarray, pos: np.ndarray, a: int, b: int
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Positions ``(w, n, 2)`` and presence ``(w, n)`` of the ``n`` distinct ids with a
    state in scans ``a … b−1`` (by position in the evaluated scans)."""
    per = [rows_of.rows(k) for k in range(a, b)]
    allrows = np.concatenate(per) if per else np.zeros(0, np.int64)
    uniq = np.unique(ids[allrows])
    w, n = b - a, len(uniq)
    xy = np.zeros((w, n, 2))
    have = np.zeros((w, n), bool)
    for t, r in enumerate(per):
        j = np.searchsorted(uniq, ids[r])
        xy[t, j] = pos[r]
        have[t, j] = True
    return xy, have


def _window_ospa2(data: ScanIndexed, a: int, b: int, c: float, p: float
                  ) -> tuple[float, float, float]:
    """(distance, localisation, cardinality) of OSPA(2) over evaluated scans ``a … b−1``."""
    from scipy.optimize import linear_sum_assignment
    X, hx = _window_states(data.truth_rows, data.truth.target_id, data.truth.positions, a, b)
    Y, hy = _window_states(data.track_rows, data.tracks.track_id, data.tracks.positions, a, b)
    m, n = X.shape[1], Y.shape[1]
    big = max(m, n)
    if big == 0:
        return 0.0, 0.0, 0.0
    if m and n:
        both = hx[:, :, None] & hy[:, None, :]  # (w, m, n)
        either = hx[:, :, None] | hy[:, None, :]
        d = np.hypot(X[:, :, None, 0] - Y[:, None, :, 0], X[:, :, None, 1] - Y[:, None, :, 1])
        per_t = np.where(both, np.minimum(d, c), np.where(either, c, 0.0))
        base = per_t.sum(axis=0) / either.sum(axis=0)  # every pair has a state in W
        cost = (base / c) ** p
        r, k = linear_sum_assignment(cost)
        loc_u = float(cost[r, k].sum())
    else:
        loc_u = 0.0
    card_u = float(abs(m - n))
    return (c * ((loc_u + card_u) / big) ** (1.0 / p), c * (loc_u / big) ** (1.0 / p),
            c * (card_u / big) ** (1.0 / p))

