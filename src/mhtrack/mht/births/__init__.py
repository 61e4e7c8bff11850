"""Birth processes of the MHT: which plots start new track trees (:mod:`.base`).

* ``every-plot`` (default, P1 Fig. 1): every plot starts a tree (:mod:`.every_plot`);
* ``logic`` / ``modified-logic`` / ``hough`` / ``modified-hough``: a P2 initiator over the
  last scans (:mod:`.initiator`), on timed plots over each radar's last rotations
  (:mod:`.timed_initiator`), scored by :mod:`.sequence`.

:func:`default_birth` is the tracker's when none is passed; :func:`mhtrack.build.make_birth`
builds the one an :class:`~mhtrack.mht.config.MHTConfig` names.
"""

from __future__ import annotations

from collections.abc import Callable

from mhtrack.mht.births.base import Birth, BirthCandidates
from mhtrack.mht.births.every_plot import EveryPlotBirth
from mhtrack.mht.births.initiator import InitiatorBirth
from mhtrack.mht.births.timed_initiator import TimedInitiatorBirth
from mhtrack.mht.config import MHTConfig
from mhtrack.mht.sprt import sprt_thresholds
from mhtrack.mht.undetected import UndetectedDensity
from mhtrack.models.motion import MotionModel
from mhtrack.names import EVERY_PLOT
from mhtrack.records import Scan


def default_birth(cfg: MHTConfig, motion: MotionModel,
                  plot_pd: Callable[[Scan], float] | None = None) -> EveryPlotBirth:
    """P1's birth (every plot may start a tree, above the SPRT deletion threshold
    ``ln(β/(1−α))``) with the configuration's parameters: the tracker's birth when none
    is passed. A configuration naming another birth is built by
    :func:`mhtrack.build.make_birth` (the builder holds every part's table)."""
    if cfg.birth != EVERY_PLOT:
        raise ValueError(f"MHTConfig.birth is {cfg.birth!r}: build the tracker with "
                         "mhtrack.build.make_tracker, or pass "
                         "birth=mhtrack.build.make_birth(config, motion)")
    return EveryPlotBirth(motion, p_detection=cfg.p_detection,
                          new_target_density=cfg.new_target_density,
                          floor=sprt_thresholds(cfg.alpha, cfg.beta)[1], v_max=cfg.v_max,
                          width=cfg.n_scan + 1, max_per_scan=cfg.max_births_per_scan,
                          plot_pd=plot_pd,
                          undetected=UndetectedDensity(cfg.new_target_density)
                          if cfg.startup_density else None)


__all__ = ["Birth", "BirthCandidates", "EveryPlotBirth", "InitiatorBirth",
           "TimedInitiatorBirth", "default_birth"]
