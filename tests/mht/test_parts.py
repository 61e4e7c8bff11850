"""The tracker's parts plugged in through their interfaces — a clutter estimator, a birth
process and a motion model of one's own — against the hand-worked two-scan example of
``test_scoring.py`` (P_D = 0.9, λ_v = 1e−7, κ = 1e−8, σw = 100, v_max = 300, σv = 10,
T = 1; plots at (0, 0) then (100, 0)): birth score ``L0 = ln(9/11)``, then
``L = 3.103452`` on the update and ``L0 + ln 0.1 = −2.503256`` on the miss."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from mhtrack.clutter import KnownClutter
from mhtrack.clutter.base import ClutterEstimator
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.mht.births.base import Birth, BirthCandidates
from mhtrack.mht.context import FrameContext
from mhtrack.mht.tree import NO_PLOT, one_point_state
from mhtrack.models.motion import ConstantVelocity, MotionModel
from mhtrack.records import Scan

L0 = math.log(9 / 11)
L_UPDATE, L_MISS = 3.103452, -2.503256
SCAN1 = Scan.from_positions(1, 0.0, [[0.0, 0.0]])
SCAN2 = Scan.from_positions(2, 1.0, [[100.0, 0.0]])


class ConstantKappa(ClutterEstimator):
    """A user's estimator: a constant κ, recording the scans it is fed; no ``forget``."""

    name = "constant-kappa"

    def __init__(self, kappa: float) -> None:
        self.kappa = kappa
        self.fed: list[int] = []

    def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
        self.fed.append(len(scan))

    def intensity(self, z: np.ndarray) -> np.ndarray:
        return np.full(len(z), self.kappa)

    def get_state(self) -> dict[str, Any]:
        return {"kappa": self.kappa}

    def set_state(self, state: dict[str, Any]) -> None:
        self.kappa = float(state["kappa"])


class FirstScanBirth(Birth):
    """A user's birth process: only the first scan's plots start trees, each at a given
    score."""

    def __init__(self, motion: MotionModel, score: float, width: int) -> None:
        super().__init__(motion)
        self.score, self.width, self.done = score, width, False

    def propose(self, frame: FrameContext, kappa: np.ndarray,
                in_gates: np.ndarray | None) -> BirthCandidates:
        if self.done:
            return BirthCandidates.empty(self.width)
        self.done = True
        z, rows = frame.z, frame.rows
        x, P = one_point_state(z, frame.R, 300.0)
        window = np.full((len(z), self.width), NO_PLOT, np.int64)
        window[:, -1] = rows
        s = np.full(len(z), self.score)
        return BirthCandidates(x, P, s, s.copy(), window, np.ones(len(z), np.int64))


def _branch_scores(trk: MHTTracker) -> list[float]:
    L = trk.leaves
    return sorted(L.score[L.tree == L.tree.min()].tolist())


def test_a_custom_clutter_estimator_scores_by_hand() -> None:
    est = ConstantKappa(1e-8)
    trk = MHTTracker(MHTConfig(imm_sigma_v=0.0), est)
    trk.step(SCAN1)
    trk.step(SCAN2)
    assert _branch_scores(trk) == pytest.approx([L_MISS, L_UPDATE], abs=1e-6)
    assert est.fed == [1, 1]


def test_an_estimator_without_forget_tracks_a_target() -> None:
    """The base ``forget`` is a documented no-op: a target at 100 m/s, clutter-free,
    confirmed at scan 3 (L ≈ 3.1 + 3.3 > ln(0.9999/0.02) ≈ 3.9), then reported every scan,
    with the tracker calling the hook on plots of a confirmed track."""
    assert ConstantKappa.forget is ClutterEstimator.forget
    scans = [Scan.from_positions(k, float(k), [[100.0 * k, 0.0]]) for k in range(1, 9)]
    trk = MHTTracker(MHTConfig(imm_sigma_v=0.0), ConstantKappa(1e-8))
    online = [len(trk.step(s)) for s in scans]
    assert online == [0, 0, 1, 1, 1, 1, 1, 1]


def test_clutter_estimator_interface_is_enforced() -> None:
    class NoIntensity(ClutterEstimator):
        name = "broken"

        def update(self, scan: Scan, in_track_gates: np.ndarray | None = None) -> None:
            pass

        def get_state(self) -> dict[str, Any]:
            return {}

        def set_state(self, state: dict[str, Any]) -> None:
            pass

    with pytest.raises(TypeError, match="intensity"):
        NoIntensity()  # type: ignore[abstract]
    assert isinstance(KnownClutter(), ClutterEstimator)


def test_a_custom_birth_process_by_hand() -> None:
    """Only scan 1's plot starts a tree: after scan 2 the tree has its miss and update
    leaves and no second tree exists (every-plot would start one at scan 2's plot)."""
    motion = ConstantVelocity(10.0)
    birth = FirstScanBirth(motion, L0, width=4)
    trk = MHTTracker(MHTConfig(imm_sigma_v=0.0), KnownClutter(1e-8), motion=motion,
                     birth=birth)
    trk.step(SCAN1)
    assert trk.leaves.score.tolist() == pytest.approx([L0])
    assert trk.last_stats is not None and trk.last_stats.n_births == 1
    trk.step(SCAN2)
    assert trk.leaves.n_trees == 1 and trk.last_stats.n_births == 0
    assert _branch_scores(trk) == pytest.approx([L_MISS, L_UPDATE], abs=1e-6)
    assert trk.birth is birth


def test_the_motion_model_is_a_part() -> None:
    """A CV model passed in replaces the configuration's IMM: the hand-worked CV scores
    (the IMM gives ``test_imm_two_scans_by_hand``'s), no per-model arrays."""
    trk = MHTTracker(MHTConfig(), KnownClutter(1e-8), motion=ConstantVelocity(10.0))
    trk.step(SCAN1)
    trk.step(SCAN2)
    assert _branch_scores(trk) == pytest.approx([L_MISS, L_UPDATE], abs=1e-6)
    assert trk.leaves.n_models == 0
    assert MHTTracker(MHTConfig(), KnownClutter(1e-8)).leaves.n_models == 2


class _ThreeArgumentCV(ConstantVelocity):
    """A user's model written against ``update(states, z, R)`` (no ``posterior``)."""

    def update(self, states, z, R):  # type: ignore[override]
        return super().update(states, z, R)


def test_a_motion_model_with_the_three_argument_update_runs() -> None:
    """A model whose ``update`` takes no ``posterior`` (its ``gating_scores`` reuses
    nothing) runs the cycle and scores as the CV model it wraps."""
    trk = MHTTracker(MHTConfig(), KnownClutter(1e-8), motion=_ThreeArgumentCV(10.0))
    trk.step(SCAN1)
    trk.step(SCAN2)
    assert _branch_scores(trk) == pytest.approx([L_MISS, L_UPDATE], abs=1e-6)
