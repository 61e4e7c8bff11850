"""Known, constant clutter intensity — P1's plain MHT (``κ = 1e−9`` per m², P1 §3)."""

from __future__ import annotations

from typing import Any

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.records import Scan


class KnownClutter(ClutterEstimator):
    """``κ̂(z) = κ`` everywhere, whatever the scans say.

    Parameters
    ----------
    kappa : clutter intensity in plots per m² per scan (``λ / A`` for uniform clutter of
        mean count ``λ`` over area ``A``).
    """

    name = "known"

    def __init__(self, kappa: float = 1e-9) -> None:
        if not (np.isfinite(kappa) and kappa > 0):
            raise ValueError(f"clutter density must be finite and > 0, got {kappa}")
        self.kappa = float(kappa)

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        return None

    def intensity(self, z: np.ndarray) -> np.ndarray:
        return np.full(len(np.asarray(z).reshape(-1, 2)), self.kappa)

    def get_state(self) -> dict[str, Any]:
        return {"kappa": self.kappa}

    def set_state(self, state: dict[str, Any]) -> None:
        from mhtrack.clutter.state_checks import check_known

        self.kappa = check_known(state)
