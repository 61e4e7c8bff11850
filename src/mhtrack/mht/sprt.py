"""Track management by Wald's sequential probability ratio test on the track score.

The score ``L`` is the log-likelihood ratio "target vs clutter" of a leaf's branch
(:mod:`mhtrack.mht.scoring`). With ``α`` the probability of confirming a false track and
``β`` of deleting a true one (Wald 1947; Blackman & Popoli 1999 §6.2)::

    confirm   L ≥ ln((1 − β)/α)
    delete    L − L_peak ≤ ln(β/(1 − α))         (a drop from the branch's best score)
              L ≤ ln(β/(1 − α))                 (a tentative leaf, on the score itself)

Confirmation may also follow an M-of-N logic (``confirm_hits``; Blackman & Popoli 1999
§6.2–6.3) and always needs ``confirm_min_plots`` plots on the branch (:class:`SPRT`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mhtrack.mht.config import MHTConfig
from mhtrack.mht.tree import Leaves


def sprt_thresholds(alpha: float, beta: float) -> tuple[float, float]:
    """Wald's SPRT thresholds ``(confirm, delete)`` on the log-likelihood ratio.

    ``confirm = ln((1 − β)/α)``, ``delete = ln(β/(1 − α))`` with ``α`` the probability of
    confirming a false track and ``β`` of deleting a true one (Wald 1947; Blackman &
    Popoli 1999 §6.2). The tracker confirms when ``L ≥ confirm`` and deletes a leaf when
    its drop from its own peak ``L − L_peak ≤ delete``.
    """
    if not (0 < alpha < 1 and 0 < beta < 1 and alpha + beta < 1):
        raise ValueError(f"need 0 < alpha, beta and alpha + beta < 1, got {alpha}, {beta}")
    return math.log((1 - beta) / alpha), math.log(beta / (1 - alpha))


def sprt_keep(score: np.ndarray, peak: np.ndarray, delete_threshold: float) -> np.ndarray:
    """Wald's SPRT deletion applied as a score drop: keep a leaf while
    ``L − L_peak > ln(β/(1−α))`` (Blackman & Popoli 1999 §6.2). For a tentative leaf whose
    score never rose, ``L_peak`` is its birth score, so this is Wald's test on the evidence
    gathered since birth; for a confirmed track it detects the target's disappearance."""
    return score - peak > delete_threshold


def tentative_keep(score: np.ndarray, tentative: np.ndarray, delete_threshold: float) -> np.ndarray:
    """Wald's lower SPRT threshold on the score itself for tentative (unconfirmed) leaves:
    keep unless ``tentative`` and ``L ≤ ln(β/(1−α))`` (Blackman & Popoli 1999 §6.2 delete
    tentative tracks on the absolute threshold, confirmed ones on the drop from the peak).
    In dense clutter a tree born with ``L₀ = ln(λ_v P_D/(κ̂ + λ_v))`` far below the threshold is
    then never grown, instead of branching for four scans until its drop reaches it."""
    return ~(tentative & (score <= delete_threshold))


@dataclass(frozen=True)
class SPRT:
    """The deletion and confirmation rules of one tracker (module docstring).

    ``confirm_hits`` (0: off), ``confirm_min_score`` and ``confirm_min_plots`` are
    :class:`~mhtrack.mht.config.MHTConfig`'s.
    """

    confirm_threshold: float
    delete_threshold: float
    confirm_hits: int = 0
    confirm_min_score: float = 0.0
    confirm_min_plots: int = 1

    @classmethod
    def from_config(cls, cfg: MHTConfig) -> SPRT:
        confirm, delete = sprt_thresholds(cfg.alpha, cfg.beta)
        return cls(confirm, delete, cfg.confirm_hits, cfg.confirm_min_score,
                   cfg.confirm_min_plots)

    def keep(self, score: np.ndarray, peak: np.ndarray, tentative: np.ndarray) -> np.ndarray:
        """Leaves that survive deletion: the drop from the peak and, for tentative ones,
        the score itself above ``ln(β/(1−α))``."""
        keep = sprt_keep(score, peak, self.delete_threshold)
        keep &= tentative_keep(score, tentative, self.delete_threshold)
        return keep

    def confirms(self, leaves: Leaves) -> np.ndarray:
        """Leaves whose tree the rule would confirm: ``L ≥ ln((1−β)/α)``, or plots in at
        least ``confirm_hits`` of the window's ``N + 1`` scans with
        ``L > confirm_min_score``; in both cases at least ``confirm_min_plots`` plots — or,
        on the SPRT's threshold, one plot with a Mode S address (its score then holds the
        address's evidence against clutter, :func:`~mhtrack.mht.attribute_scores.
        reply_terms`; issue 29 item 3)."""
        sprt = leaves.score >= self.confirm_threshold
        confirm = sprt
        if self.confirm_hits > 0:
            hits = (leaves.window >= 0).sum(axis=1)
            confirm = confirm | ((hits >= self.confirm_hits)
                                 & (leaves.score > self.confirm_min_score))
        enough = leaves.n_updates >= self.confirm_min_plots
        return confirm & enough | sprt & (leaves.ident[:, 1] >= 0)
