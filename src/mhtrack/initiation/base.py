"""The two kinds of part of multi-radar initiation (P2): a fuser and an initiator.

Each is an :class:`abc.ABC` with one concrete template method and the hooks a subclass
fills in (the project's one plug-in mechanism; scikit-learn's ``fit``/``predict`` split
over a base class, ``sklearn/mixture/_base.py``):

* :class:`Fuser` — ``fuse(scan)`` calls the subclass's :meth:`Fuser.fit` (which labels
  the plots, one cluster per target) and builds the fused scan from the labels
  (:func:`~mhtrack.initiation.fused.fused_scan`). Implementations:
  :class:`~mhtrack.initiation.fusion.AdaptiveKMeansFusion`,
  :class:`~mhtrack.initiation.fusion.KMeansFusion`.
* :class:`Initiator` — ``initiate(window)`` checks the parameters
  (:meth:`Initiator.check_parameters`), stacks the scans into a
  :class:`~mhtrack.initiation.window.Window` of ``n_scans`` scans, asks the subclass for
  the candidate tracks (:meth:`Initiator.find_tracks`), drops duplicates and sub-tracks
  (:func:`~mhtrack.initiation.window.remove_dominated`) and estimates each track's
  straight-line state (:func:`~mhtrack.initiation.window.least_squares_state`).
  Implementations: :class:`~mhtrack.initiation.logic.LogicInitiator`,
  :class:`~mhtrack.initiation.hough.HoughInitiator`.
"""

from __future__ import annotations

import abc
import logging
from collections.abc import Sequence

import numpy as np

from mhtrack.initiation.fused import FusedScan, fused_scan
from mhtrack.initiation.window import (
    NO_PLOT,
    InitiatedTracks,
    Window,
    least_squares_state,
    remove_dominated,
)
from mhtrack.records import Scan

#: Warnings of the fusers (caps that acted in a burst).
logger = logging.getLogger("mhtrack.initiation")


class Fuser(abc.ABC):
    """A plot fuser: labels the plots of one scan, one cluster per target, and returns one
    fused plot per cluster (:meth:`fuse`).

    A subclass implements :meth:`fit`, which sets ``labels_`` ((n,) cluster ``0..k−1`` of
    each plot) and may set ``threshold_`` (the distance threshold it used; NaN when it has
    none). ``weighting`` is how a cluster's plots combine
    (:data:`~mhtrack.initiation.fused.WEIGHTINGS`; default ``"mean"``, P2's).
    """

    weighting: str = "mean"
    labels_: np.ndarray
    threshold_: float = float("nan")

    @abc.abstractmethod
    def fit(self, z: np.ndarray, sensor: np.ndarray | None = None,
            R: np.ndarray | None = None) -> Fuser:
        """Cluster plots ``z`` (n, 2) of radars ``sensor`` (n,) (all one radar if None) with
        covariances ``R`` (n, 2, 2) (optional); set ``labels_``; return ``self``."""

    def fuse(self, scan: Scan) -> FusedScan:
        """Cluster ``scan``'s plots (:meth:`fit`) and return the fused scan. When caps of
        the clustering acted (a burst; ``caps_``, name → count), one warning line says so."""
        self.fit(scan.z, scan.sensor, scan.R)
        out = fused_scan(scan, self.labels_, self.threshold_, weighting=self.weighting)
        caps = getattr(self, "caps_", None)
        if caps:
            logger.warning("scan %d (%d plots fused into %d): fusion caps acted: %s",
                           scan.index, len(scan), out.n_clusters,
                           ", ".join(f"{k} {caps[k]}" for k in sorted(caps)))
        return out

    @staticmethod
    def check_plots(z: object, sensor: object) -> tuple[np.ndarray, np.ndarray]:
        """``z`` as a finite (n, 2) float array and ``sensor`` as (n,) ids (all 0 if None),
        or ``ValueError`` saying what is wrong (for :meth:`fit` at its edge)."""
        za = np.asarray(z, float)
        if za.size == 0:
            za = za.reshape(0, 2)
        if za.ndim != 2 or za.shape[1] != 2:
            raise ValueError(f"plots must have shape (n, 2), got {za.shape}")
        if not np.isfinite(za).all():
            raise ValueError("plots contain non-finite coordinates")
        s = np.zeros(len(za), np.int64) if sensor is None else np.asarray(sensor).reshape(-1)
        if len(s) != len(za):
            raise ValueError(f"sensor has {len(s)} entries for {len(za)} plots")
        return za, s


class Initiator(abc.ABC):
    """A track initiator over a window of ``n_scans`` consecutive scans (P2 §2–3).

    A subclass sets ``n_scans`` and implements :meth:`find_tracks`; it may override
    :meth:`check_parameters`. :meth:`initiate` is the one template every initiator runs.
    """

    #: ``N``, the number of scans of a window (P2: 4).
    n_scans: int

    def initiate(self, scans: Sequence[Scan] | Window) -> InitiatedTracks:
        """Tracks started in the window of ``scans`` (``n_scans`` scans, in time order):
        :meth:`find_tracks`, without duplicates and strict sub-tracks, with their
        least-squares states at the last scan."""
        self.check_parameters()
        w = scans if isinstance(scans, Window) else Window.from_scans(scans)
        if w.n_scans != self.n_scans:
            raise ValueError(f"window has {w.n_scans} scans, expected {self.n_scans}")
        flat = self.find_tracks(w)
        flat = flat[remove_dominated(flat)] if len(flat) else flat
        x, P = least_squares_state(w, flat)
        plots = np.where(flat >= 0, w.index[np.maximum(flat, 0)], NO_PLOT)
        return InitiatedTracks(w.scans, float(w.times[-1]), plots, flat, x, P)

    def check_parameters(self) -> None:
        """Raise ``ValueError`` naming an invalid parameter. Optional hook: the default
        checks nothing."""
        return None

    @abc.abstractmethod
    def find_tracks(self, window: Window) -> np.ndarray:
        """Candidate tracks of ``window`` as (n, ``n_scans``) int64 flat plot indices
        (``window.z[i]``; ``-1`` = no plot at that scan); duplicates and sub-tracks may
        remain (the template removes them)."""


def check_window_and_speeds(n_scans: int, min_plots: int, v_min: float, v_max: float) -> None:
    """Validate the window (``N``, ``M``) and velocity-gate parameters the initiators share."""
    if not (isinstance(n_scans, int) and n_scans >= 2):
        raise ValueError(f"n_scans must be an integer >= 2, got {n_scans!r}")
    if not (isinstance(min_plots, int) and 2 <= min_plots <= n_scans):
        raise ValueError(f"min_plots must be an integer in [2, n_scans], got {min_plots!r}")
    if not (0 <= v_min < v_max and np.isfinite(v_max)):
        raise ValueError(f"need 0 <= v_min < v_max < inf, got v_min={v_min}, v_max={v_max}")
