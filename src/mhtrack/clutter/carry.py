"""The last fit's Gaussian densities carried to the next scan's warm start.

A fit over the window's pooled plots ends with its Gaussians' (K, n) ``log N(z_i; μ_j,
Σ_j)`` and ``dᵀΣ_j⁻¹d`` at those plots (:attr:`~mhtrack.clutter.em.EMResult.gauss`). The
next scan's warm start needs the same quantities for the same Gaussians at its pool, which
is the last pool without the oldest scan (when the window was full) and without the plots
:meth:`~mhtrack.clutter.mixture.MixtureClutter.forget` took out of the last scan, followed
by the new scan's plots. Each entry is an elementwise formula of one plot and one
Gaussian (:func:`~mhtrack.clutter.density.maha_det_t`,
:func:`~mhtrack.clutter.density.log_pdf_t`), so the carried plots' columns are the floats a
recomputation gives; only the new scan's columns are computed.
"""

from __future__ import annotations

import numpy as np

from mhtrack.clutter.density import log_pdf_t, maha_det_t, offsets_t

_min = np.minimum.reduce  # what ``.min()`` calls

#: columns of the last fit's pool still pooled, and that fit's (K, n) log N and dᵀΣ⁻¹d
Carried = tuple[np.ndarray, np.ndarray, np.ndarray]


class FitColumns:
    """The last fit's (K, n) ``log N`` and ``dᵀΣ⁻¹d``, the window's scan sizes at that fit
    and the rows of its last scan still in the window."""

    def __init__(self) -> None:
        self._fit: tuple[np.ndarray, np.ndarray, list[int]] | None = None
        self._last_rows: np.ndarray | None = None  # None: all of them

    def clear(self) -> None:
        """Nothing to carry (no fit, or a fit on a subsample)."""
        self._fit, self._last_rows = None, None

    def record(self, glp: np.ndarray, maha: np.ndarray, sizes: list[int]) -> None:
        """A fit's arrays over the pool of scans of ``sizes`` plots (window order)."""
        self._fit, self._last_rows = (glp, maha, sizes), None

    def drop_last(self, kept: np.ndarray) -> None:
        """The last scan keeps only its rows ``kept`` (indices, increasing)."""
        if self._fit is not None:
            rows = self._last_rows
            self._last_rows = kept if rows is None else rows.take(kept)

    def carried(self, window: int) -> Carried | None:
        """The last fit's pool columns of the plots that stay pooled once the next scan
        joins a window of ``window`` scans (pool order), with that fit's arrays; ``None``
        if there is nothing to carry."""
        if self._fit is None:
            return None
        glp, maha, sizes = self._fit
        if len(sizes) == window == 1:
            return None  # the last fit's plots all leave
        first = sizes[0] if len(sizes) == window else 0  # the oldest scan leaves
        last = sum(sizes) - sizes[-1]
        rows = self._last_rows
        tail = np.arange(last, last + sizes[-1]) if rows is None else rows + last
        return np.concatenate((np.arange(first, last), tail)), glp, maha


def gauss_at(z_t: np.ndarray, means: np.ndarray, cov: np.ndarray, carried: Carried | None,
             near: bool) -> tuple[np.ndarray | None, np.ndarray]:
    """(n,) ``min_j dᵀΣ_j⁻¹d`` (if ``near``) and (K, n) ``log N`` of the Gaussians
    ``means``, ``cov`` at the pool ``z_t`` (:func:`~mhtrack.clutter.density.plots_t`).
    ``carried``: the pool's first plots' columns in the last fit of these Gaussians
    (:meth:`FitColumns.carried`), taken from it; the rest computed."""
    if carried is None:
        maha, det = maha_det_t(*offsets_t(z_t, means), cov)
        return (_min(maha, axis=0) if near else None), log_pdf_t(maha, det)
    cols, glp_old, maha_old = carried
    maha, det = maha_det_t(*offsets_t(z_t[:, :, len(cols):], means), cov)
    glp = np.concatenate((glp_old.take(cols, axis=1), log_pdf_t(maha, det)), axis=1)
    if not near:
        return None, glp
    return np.concatenate((_min(maha_old, axis=0).take(cols), _min(maha, axis=0))), glp
