"""The discount ``γ_k`` of the recursive (forgetting) clutter estimators, one rule for all.

An estimator that forgets — the forgetting mixture (:mod:`mhtrack.clutter.forgetting`),
the clutter map (:mod:`mhtrack.clutter.radar_map`) and the map-calibrated mixture that
keeps its counts — multiplies its sums by ``γ_k`` before adding scan (rotation) ``k``.
Either a half-life ``h`` in seconds of data time is given, and

    γ_k = 2^(−Δt_k / h)        (``Δt_k`` since the previous update, 1 at the first),

so the memory is the same whatever the radar's period; or a constant ``γ`` per update
(memory ``1/(1 − γ)`` updates). Giving both is an error (:func:`check_discount`).
"""

from __future__ import annotations

import numpy as np


def check_discount(forgetting: float | None, half_life: float | None) -> None:
    """``ValueError`` unless at most one of ``forgetting`` (in (0, 1]) and ``half_life``
    (> 0 s, ``inf`` allowed) is given."""
    if forgetting is not None and half_life is not None:
        raise ValueError(f"give forgetting ({forgetting!r}) or half_life ({half_life!r}), "
                         "not both")
    if forgetting is not None and not (np.isfinite(forgetting) and 0 < forgetting <= 1):
        raise ValueError(f"forgetting must be in (0, 1], got {forgetting!r}")
    if half_life is not None and not half_life > 0:
        raise ValueError(f"half_life must be > 0 s, got {half_life!r}")


def discount(last: float | None, t: float, *, forgetting: float | None,
             half_life: float | None) -> float:
    """``γ_k`` (module docstring) of an update at data time ``t`` after one at ``last``
    (``None``: the first): ``2^(−Δt/h)`` with a half-life, else ``forgetting``."""
    if half_life is not None:
        return 1.0 if last is None else float(2.0 ** (-max(t - last, 0.0) / half_life))
    if forgetting is None:
        raise ValueError("discount: neither forgetting nor half_life given")
    return float(forgetting)
