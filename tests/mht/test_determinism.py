"""No result depends on wall-clock time: the solver stops by counting, and a run reports
how often the hard caps acted."""

import numpy as np

from mhtrack.experiments.pipeline import TrackingRun
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.mht.hypothesis import GlobalHypothesis
from mhtrack.mht.report import StepStats
from mhtrack.records import Scan, TrackTable


def _stats(scan: int, caps: dict[str, int]) -> StepStats:
    return StepStats(scan, 0, 0, 0, 0, 0, 0, 0.0, caps)


def test_run_caps_sum_each_cap_and_count_the_scans_where_any_acted():
    run = TrackingRun("mht", TrackTable.empty(), (
        _stats(0, {}), _stats(1, {"max_leaves": 3}),
        _stats(2, {"max_leaves": 2, "milp_node_limit": 1}), _stats(3, {})))
    assert run.caps == {"max_leaves": 5, "milp_node_limit": 1, "scans": 2}
    assert TrackingRun("mht", TrackTable.empty(), (_stats(0, {}),)).caps == {}


def test_the_node_limit_is_reported_as_a_cap(monkeypatch):
    """The tracker's hypothesis stage counts the clusters the node limit stopped."""
    from mhtrack.mht import frame_scope

    def stopped(*a, **k):
        return GlobalHypothesis(np.zeros(0, np.int64), 0.0, n_node_limited=2)

    monkeypatch.setattr(frame_scope, "best_hypothesis", stopped)
    trk = MHTTracker(MHTConfig(imm_sigma_v=0.0))
    trk.step(Scan.from_positions(0, 0.0, np.zeros((0, 2))))
    assert trk.last_stats is not None and trk.last_stats.caps == {"milp_node_limit": 2}


def test_the_config_has_no_time_limit():
    names = set(MHTConfig.__dataclass_fields__)
    assert "milp_node_limit" in names
    assert not [n for n in names if "time_limit" in n]


def test_same_scans_give_the_same_tracks_with_a_tiny_node_limit():
    """Plain MHT (κ = 1e−9) on a dense scene, node limit 1: two trackers agree exactly."""
    rng = np.random.default_rng(4)
    scans = [Scan.from_positions(k, float(k), np.r_[
        rng.uniform(-3000, 3000, (40, 2)),
        np.array([[100.0 * k, 0.0], [0.0, 100.0 * k]]) + rng.normal(0, 50, (2, 2))])
        for k in range(8)]
    out = []
    for _ in range(2):
        trk = MHTTracker(MHTConfig(milp_node_limit=1, imm_sigma_v=0.0))
        out.append(trk.run(scans))
    a, b = out
    assert a.track_id.tolist() == b.track_id.tolist()
    assert np.array_equal(a.x, b.x) and np.array_equal(a.score, b.score)
