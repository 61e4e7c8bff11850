"""Birth processes of the MHT: which plots start new track trees (:mod:`.base`).

* ``every-plot`` (default, P1 Fig. 1): every plot starts a tree (:mod:`.every_plot`);
* ``logic`` / ``modified-logic`` / ``hough`` / ``modified-hough``: a P2 initiator over the
  last scans (:mod:`.initiator`), scored by :mod:`.sequence`.

:func:`make_birth` builds the one an :class:`~mhtrack.mht.config.MHTConfig` names.
"""

from __future__ import annotations

from collections.abc import Callable

from mhtrack.mht.births.base import Birth, BirthCandidates
from mhtrack.mht.births.every_plot import EveryPlotBirth
from mhtrack.mht.births.initiator import InitiatorBirth
from mhtrack.mht.config import MHTConfig
from mhtrack.mht.scoring import miss_increment
from mhtrack.mht.sprt import sprt_thresholds
from mhtrack.models.motion import MotionModel
from mhtrack.names import EVERY_PLOT
from mhtrack.records import Scan


def make_birth(cfg: MHTConfig, motion: MotionModel,
               plot_pd: Callable[[Scan], float] | None = None) -> Birth:
    """The birth process ``cfg.birth`` with the configuration's parameters; new trees
    start only above the SPRT deletion threshold ``ln(β/(1−α))``. ``plot_pd``: the
    ``P_D`` of a scan's sensor for the every-plot birth score (``None``:
    ``cfg.p_detection``)."""
    floor = sprt_thresholds(cfg.alpha, cfg.beta)[1]
    if cfg.birth == EVERY_PLOT:
        return EveryPlotBirth(motion, p_detection=cfg.p_detection,
                              new_target_density=cfg.new_target_density, floor=floor,
                              v_max=cfg.v_max, width=cfg.n_scan + 1,
                              max_per_scan=cfg.max_births_per_scan, plot_pd=plot_pd)
    return InitiatorBirth(
        cfg.birth, motion, theta_deg=cfg.birth_theta_deg, width=cfg.n_scan + 1,
        p_detection=cfg.p_detection, new_target_density=cfg.new_target_density,
        miss_dl=miss_increment(cfg.p_detection, cfg.gate_probability
                               if cfg.miss_uses_gate_probability else None),
        v_max=cfg.v_max, floor=floor, max_per_scan=cfg.max_births_per_scan,
        prune_drop=cfg.prune_drop, max_leaves_per_tree=cfg.max_leaves_per_tree)


__all__ = ["Birth", "BirthCandidates", "EveryPlotBirth", "InitiatorBirth", "make_birth"]
