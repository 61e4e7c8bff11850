"""The one interface through which the tracker sees clutter: ``κ̂(z)`` at scan ``k``.

Every scan the tracker calls :meth:`ClutterEstimator.update` with the scan's plots and a
mask of the plots that fall inside confirmed tracks' gates (estimators may leave those out
as likely target plots), then :meth:`ClutterEstimator.intensity` on the plots it scores.
The intensity is in plots per m² per scan, the ``κ`` of P1 eqs. 3, 5, 14–15. An estimator
that learns from past scans may also have ``forget(used)``: after the scan's best global
hypothesis, the tracker passes the mask of the plots confirmed tracks used (optional: the
tracker calls it only when it exists).
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np

from mhtrack.records import Scan


@runtime_checkable
class ClutterEstimator(Protocol):
    """Online estimate of the clutter intensity ``κ̂_k(z)``."""

    name: str

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        """Take scan ``k``'s plots; ``in_track_gates`` (n,) marks plots inside confirmed
        tracks' gates, or is ``None`` when no track is confirmed."""

    def intensity(self, z: np.ndarray) -> np.ndarray:
        """``κ̂_k(z)`` (plots per m² per scan) at positions ``z`` (n, 2) for the last scan."""

    def get_state(self) -> dict[str, Any]:
        """Everything needed to continue identically, as JSON-able values and arrays."""

    def set_state(self, state: dict[str, Any]) -> None:
        """Restore what :meth:`get_state` returned."""
