"""One DEBUG line per frame (``mhtrack -vv``, logger ``mhtrack.pipeline``)::

    frame 12 t=36.000 s radar 1: 9 plots, 2 confirmed + 5 tentative tracks, 41 hypotheses
    in 7 trees, clutter 1.02e-09 /m² (mean at the plots), 0.84 ms

* *plots*: those the tracker stepped (after fusion), ``StepStats.n_plots``;
* *confirmed / tentative*: the tracks of the best global hypothesis (one chosen leaf per
  tree), by whether the SPRT has confirmed them (``Leaves.chosen``, ``Leaves.track``);
  with every radar looked at, *confirmed* is the number of tracks reported at the frame;
* *hypotheses in trees*: the leaves kept after pruning and their trees
  (``StepStats.n_leaves``, ``n_trees``);
* *clutter*: the mean of the intensity κ̂ the tracker scored the frame's plots with
  (``MHTTracker.last_kappa``, per m² per scan, the floor included); ``-`` without plots;
* the time is the tracker's step (``StepStats.time_s``).

The caller checks ``log.isEnabledFor(DEBUG)`` first, so that nothing here runs otherwise.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from mhtrack.mht import StepStats
    from mhtrack.records import Scan

#: The line's format (lazy %-arguments: formatted only when a handler takes it).
FORMAT = ("frame %d t=%.3f s radar %s: %d plots, %d confirmed + %d tentative tracks, "
          "%d hypotheses in %d trees, clutter %s /m² (mean at the plots), %.2f ms")


def log_frame(log: logging.Logger, scan: Scan, tracker: Any, stats: StepStats) -> None:
    """Log the line of the module docstring for the frame ``scan`` just stepped by
    ``tracker`` (an :class:`~mhtrack.mht.MHTTracker`), whose statistics are ``stats``."""
    radars = ",".join(str(s) for s in np.unique(scan.sensor).tolist()) or "-"
    leaves = tracker.leaves
    chosen = np.asarray(leaves.chosen, bool)
    confirmed = int(np.count_nonzero(chosen & (leaves.track >= 0)))
    kappa = getattr(tracker, "last_kappa", None)
    clutter = f"{float(np.mean(kappa)):.3g}" if kappa is not None and len(kappa) else "-"
    log.debug(FORMAT, int(scan.index), float(scan.time), radars, stats.n_plots, confirmed,
              int(np.count_nonzero(chosen)) - confirmed, stats.n_leaves, stats.n_trees,
              clutter, 1e3 * stats.time_s)
