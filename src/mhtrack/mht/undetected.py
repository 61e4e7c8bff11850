"""The density of targets not yet detected, for a tracker that starts on a busy sky.

P1 scores a plot's "new target" explanation with a constant density ``λ_v`` (P1 eqs. 5,
15; :mod:`mhtrack.mht.scoring`): the targets that *appear* each scan. At start-up every
target present is new, and that is many more than ``λ_v`` (a national network starts on
thousands of aircraft). The Poisson part of the PMBM filter (García-Fernández, Williams,
Granström, Svensson 2018, "Poisson multi-Bernoulli mixture filter: direct derivation and
implementation", the undetected-target intensity ``D_u``) gives the rule, here uniform
over the surveillance area (one number per m²)::

    predict   D(k|k−1) = D(k−1|k−1) + λ_b               (P_S = 1, births λ_b = λ_v)
    update    D(k|k)   = (1 − P_D) · D(k|k−1)            (the undetected stay undetected)

and the density of a plot being a target's *first* detection is ``P_D · D(k|k−1)``: the
tracker scores scan ``k`` with ``λ_k = P_D · D(k|k−1)`` where P1 has ``λ_v``. In the
steady state ``D(k|k−1) = λ_v / P_D``, so ``λ_k → λ_v``: P1's score (to rounding).

The start: ``D(1|0)`` is estimated from the first scan's plots ``z_i`` with the clutter
intensity ``κ̂(z_i)`` — the maximum-likelihood weight ``u = P_D D`` of a uniform target
component over area ``V`` beside the clutter, the root ``u > 0`` of
``Σ_i u / (κ̂_i + u) = u V`` (:func:`excess_density`; with a uniform ``κ`` it is the
plots in excess of the clutter, ``u = (n − κV)/V``), and ``D(1|0) = max(u, λ_v)/P_D``.
``V`` is the first scan's plots' bounding box unless given.

Assumes each frame looks at the whole area (scans); frames of sectors decay ``D`` by
``1 − P_D`` each, too fast by their number (``docs/mht.md``, *Start-up density*).
"""

from __future__ import annotations

import numpy as np


def excess_density(kappa: np.ndarray, area: float) -> float:
    """``u ≥ 0``, the density (per m²) of a scan's plots beyond the clutter's: the
    maximum-likelihood weight of a uniform component of density ``u`` over ``area``
    beside the known clutter intensities ``kappa`` at the plots (module docstring),
    the root of ``Σ_i u/(κ_i + u) = u·area`` (0 when ``Σ_i 1/κ_i ≤ area``: no excess).
    Bracketed in ``(0, n/area]`` and found by ``scipy.optimize.brentq``."""
    k = np.asarray(kappa, float).reshape(-1)
    if not (np.isfinite(area) and area > 0):
        raise ValueError(f"area must be finite and > 0, got {area}")
    if k.size == 0 or float(np.sum(1.0 / k)) <= area:
        return 0.0
    from scipy.optimize import brentq

    hi = k.size / area

    def g(u: float) -> float:
        return float(np.sum(u / (k + u))) - u * area

    if g(hi) >= 0.0:  # only when some κ is 0 (floored in the tracker)
        return hi
    return float(brentq(g, hi * 1e-12, hi, xtol=hi * 1e-12, rtol=1e-12, maxiter=200))


def box_area(z: np.ndarray) -> float:
    """Area (m²) of the bounding box of plots ``z`` (n, 2), each side at least 1 m."""
    z = np.asarray(z, float)
    if z.shape[0] == 0:
        return 1.0
    span = np.maximum(z.max(axis=0) - z.min(axis=0), 1.0)
    return float(span[0] * span[1])


class UndetectedDensity:
    """The undetected-target density ``D`` (module docstring) of one tracker.

    Parameters
    ----------
    birth_density : ``λ_b``, targets appearing per m² per scan (the tracker's ``λ_v``).
    area : surveillance area ``V`` (m²) of the start-up estimate; ``None``: the first
        scan's plots' bounding box (:func:`box_area`).
    """

    def __init__(self, birth_density: float, area: float | None = None) -> None:
        self.birth_density = float(birth_density)
        self.area = area
        #: ``D(k|k)`` after the last scan; ``None`` before the first.
        self.density: float | None = None

    def first_detection(self, z: np.ndarray, kappa: np.ndarray, p_detection: float) -> float:
        """``λ_k = P_D · D(k|k−1)`` of this scan (predicting ``D``; the first scan
        estimates it from its plots ``z`` and their clutter intensities ``kappa``), then
        ``D`` updated to ``(1 − P_D) D(k|k−1)``."""
        if self.density is None:
            if len(kappa) == 0:  # nothing to estimate from yet: P1's density
                return self.birth_density
            area = box_area(z) if self.area is None else self.area
            u = excess_density(kappa, area)
            pred = max(u, self.birth_density) / p_detection
        else:
            pred = self.density + self.birth_density
        self.density = (1.0 - p_detection) * pred
        return p_detection * pred

    def arrays(self) -> dict[str, np.ndarray]:
        """``D(k|k)`` to save (empty before the first scan)."""
        return {} if self.density is None else {"undetected_density": np.array(self.density)}

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """Restore what :meth:`arrays` gave."""
        d = arrays.get("undetected_density")
        if d is None:
            self.density = None
            return
        d = np.asarray(d)
        if d.shape != () or d.dtype.kind != "f" or not (np.isfinite(d) and d >= 0):
            raise ValueError(f"undetected_density must be one finite float >= 0, got {d!r}")
        self.density = float(d)
