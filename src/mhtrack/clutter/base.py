"""The one interface through which the tracker sees clutter: ``κ̂(z)`` at scan ``k``.

Every scan the tracker calls :meth:`ClutterEstimator.update` with the scan's plots and a
mask of the plots that fall inside confirmed tracks' gates (estimators may leave those out
as likely target plots), then :meth:`ClutterEstimator.intensity` on the plots it scores.
The intensity is in plots per m² per scan, the ``κ`` of P1 eqs. 3, 5, 14–15. After the
scan's best global hypothesis it calls :meth:`ClutterEstimator.forget` with the mask of
the plots confirmed tracks used — an optional hook for estimators that learn from past
scans (a no-op by default). :meth:`ClutterEstimator.reference_intensity` is the clutter
level a birth scaling compares ``κ̂`` with (a clutter map's mean; 0 by default: none), so
that a wrapper forwards it like any other method.

To plug in an estimator, subclass :class:`ClutterEstimator`, set ``name`` and implement
the four abstract methods::

    class Constant(ClutterEstimator):
        name = "constant"
        def update(self, scan, in_track_gates=None): pass
        def intensity(self, z): return np.full(len(z), 1e-8)
        def get_state(self): return {}
        def set_state(self, state): pass
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any

import numpy as np

from mhtrack.records import Scan


class ClutterEstimator(ABC):
    """Online estimate of the clutter intensity ``κ̂_k(z)`` (module docstring)."""

    @property
    @abstractmethod
    def name(self) -> str:
        """The estimator's name, saved with the tracker's state (a class attribute)."""

    @abstractmethod
    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        """Take scan ``k``'s plots; ``in_track_gates`` (n,) marks plots inside confirmed
        tracks' gates, or is ``None`` when no track is confirmed."""

    @abstractmethod
    def intensity(self, z: np.ndarray) -> np.ndarray:
        """``κ̂_k(z)`` (plots per m² per scan) at positions ``z`` (n, 2) for the last scan."""

    @abstractmethod
    def get_state(self) -> dict[str, Any]:
        """Everything needed to continue identically, as JSON-able values and arrays."""

    @abstractmethod
    def set_state(self, state: dict[str, Any]) -> None:
        """Restore what :meth:`get_state` returned."""

    def forget(self, used: np.ndarray) -> None:  # noqa: B027 (optional hook)
        """Optional hook: ``used`` (n,) marks the last scan's plots that the best
        hypothesis gives to confirmed tracks (target plots, not clutter). Default: nothing
        (an estimator that keeps no past scans has nothing to forget)."""

    def reference_intensity(self) -> float:
        """The clutter level (per m² per scan) the clutter-scaled birth density compares
        ``κ̂(z)`` with (:func:`~mhtrack.clutter.radar_map.birth_scale`): a clutter map's
        mean intensity ``ρ̄``. Default 0: the estimator has none, and the scaling does
        nothing."""
        return 0.0
