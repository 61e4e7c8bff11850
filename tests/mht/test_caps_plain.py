"""The overload rule of the caps (mhtrack.mht.caps, pruning.cap_per_plot): what it keeps,
its bound, when it acts, and the tracker reporting it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from test_caps import _scene_scans

from mhtrack.clutter import KnownClutter
from mhtrack.experiments import track
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.mht.caps import (
    CHILDREN_PER_PLOT,
    LEAVES_PER_PLOT,
    LEAVES_PER_TRACK,
    MISSES_PER_TREE,
    scene_leaves,
)
from mhtrack.mht.pruning import (
    cap_leaves,
    cap_leaves_per_tree,
    cap_per_plot,
    leaf_caps_act,
)
from mhtrack.records import PlotTable, Scan


def _children(draw_sizes: list[int], n_plots: int, seed: int) -> tuple[np.ndarray, ...]:
    """Children sorted by tree: ``draw_sizes[t]`` children of tree ``t``, plots in
    ``-1 … n_plots − 1`` (−1: a miss), scores with ties (rounded to 0.5)."""
    rng = np.random.default_rng(seed)
    tree = np.repeat(np.arange(len(draw_sizes)), draw_sizes)
    plot = rng.integers(-1, n_plots, tree.size)
    score = np.round(rng.normal(0, 3, tree.size) * 2) / 2
    return tree, plot, score


def _reference_keep(tree, plot, score, per_plot, per_miss):
    """Brute force: per plot (and per tree for misses), sort its children by score
    descending then index, keep the first ones."""
    keep = np.zeros(tree.size, bool)
    groups: dict[tuple[str, int], list[int]] = {}
    for i in range(tree.size):
        key = ("plot", int(plot[i])) if plot[i] >= 0 else ("miss", int(tree[i]))
        groups.setdefault(key, []).append(i)
    for (kind, _), idx in groups.items():
        idx.sort(key=lambda i: (-score[i], i))
        for i in idx[: per_plot if kind == "plot" else per_miss]:
            keep[i] = True
    return keep


@given(sizes=st.lists(st.integers(0, 30), min_size=0, max_size=12),
       n_plots=st.integers(1, 8), seed=st.integers(0, 2**32 - 1),
       per_plot=st.integers(1, 5), per_miss=st.integers(1, 3))
def test_cap_per_plot_matches_brute_force_and_its_bound(sizes, n_plots, seed, per_plot,
                                                        per_miss):
    tree, plot, score = _children(sizes, n_plots, seed)
    keep, cut = cap_per_plot(tree, plot, score, per_plot, per_miss)
    np.testing.assert_array_equal(keep, _reference_keep(tree, plot, score, per_plot,
                                                        per_miss))
    assert cut == tree.size - keep.sum()
    n_trees = np.unique(tree).size
    assert keep.sum() <= per_plot * n_plots + per_miss * n_trees


def test_cap_per_plot_hand_worked():
    # tree 0: miss 1.0, plot 0 (5.0), plot 1 (2.0); tree 1: misses 0.5 and 0.7, plot 0
    # (5.0, a tie with tree 0's: lower index first), plot 0 (4.0)
    tree = np.array([0, 0, 0, 1, 1, 1, 1])
    plot = np.array([-1, 0, 1, -1, -1, 0, 0])
    score = np.array([1.0, 5.0, 2.0, 0.5, 0.7, 5.0, 4.0])
    keep, cut = cap_per_plot(tree, plot, score, per_plot=2, per_tree_miss=1)
    # plot 0 keeps indices 1 and 5 (5.0, 5.0), drops 6; tree 1 keeps its 0.7 miss
    np.testing.assert_array_equal(keep, [True, True, True, False, True, True, False])
    assert cut == 2


@given(sizes=st.lists(st.integers(0, 40), min_size=0, max_size=10),
       budget=st.integers(0, 200), per_tree=st.integers(1, 40),
       seed=st.integers(0, 2**32 - 1))
def test_the_rule_acts_exactly_where_the_leaf_caps_act(sizes, budget, per_tree, seed):
    """``leaf_caps_act`` is true iff the per-tree cap, or the cap on all leaves after
    it, cuts something."""
    tree, _, score = _children(sizes, 3, seed)
    keep, cut_tree = cap_leaves_per_tree(tree, score, per_tree)
    _, cut_all = cap_leaves(score[keep], np.zeros(int(keep.sum()), bool), budget)
    assert leaf_caps_act(tree, budget, per_tree) == bool(cut_tree or cut_all)


def _blob_scans(n_scans: int, n_clutter: int, seed: int) -> list[Scan]:
    """One target in a dense blob of clutter (σ = 50 m) beside it, P_D = 1."""
    rng = np.random.default_rng(seed)
    scans = []
    for k in range(1, n_scans + 1):
        target = np.array([[-2000.0 + 50.0 * k, 0.0]]) + rng.normal(0, 100, (1, 2))
        blob = rng.normal(0, 50, (n_clutter, 2)) + np.array([500.0, 500.0])
        s = Scan.from_positions(k, float(k), np.vstack((target, blob)))
        scans.append(dataclasses.replace(s, origin=np.r_[1, np.full(n_clutter, -1)]))
    return scans


def test_plain_mht_in_a_blob_is_bounded_and_reported():
    """κ = 1e−9 with 15 clutter plots in a blob: every tree branches on every plot and the
    per-tree cap would act; the rule keeps at most 4 children per plot and 2 misses per
    tree, the run says so, and the target is still tracked."""
    scans = _blob_scans(8, 15, 1)
    cfg = MHTConfig(max_leaves_per_tree=50, imm_sigma_v=0.0)
    run = track(MHTTracker(cfg, KnownClutter(1e-9)), PlotTable.from_scans(scans))
    acted = run.cap_scans.get("max_leaves_per_plot", [])
    assert acted and run.caps["max_leaves_per_plot"] > 0
    for st_ in run.stats:
        if st_.scan in acted:  # leaves of the old trees, plus this scan's births
            assert st_.n_leaves <= (CHILDREN_PER_PLOT * st_.n_plots
                                    + MISSES_PER_TREE * st_.n_trees + st_.n_births)
    old = MHTConfig(max_leaves_per_tree=50, imm_sigma_v=0.0, scale_caps=False)
    run_old = track(MHTTracker(old, KnownClutter(1e-9)), PlotTable.from_scans(scans))
    assert "max_leaves_per_plot" not in run_old.caps  # the rule belongs to scale_caps
    assert sum(s.n_leaves for s in run.stats) < sum(s.n_leaves for s in run_old.stats) / 3
    # the target (plot row 0 of every scan) is in a confirmed track at the end
    last = run.tracks.scan == run.tracks.scan.max()
    assert np.any(np.hypot(run.tracks.x[last] - (-2000.0 + 50.0 * 8), run.tracks.y[last])
                  < 400.0)


def _same_tracks(a, b) -> None:
    assert len(a) > 0
    for f in ("scan", "track_id", "x", "y", "vx", "vy", "score", "plot"):
        np.testing.assert_array_equal(getattr(a, f), getattr(b, f))


def test_where_no_leaf_cap_acts_the_rule_changes_nothing():
    """Four crossing targets in uniform clutter with the true κ: no leaf cap acts, so
    scale_caps on and off (same limits below 900 plots) give the same tracks, bit for
    bit."""
    scans = _scene_scans(40, 12, 4)
    runs = [track(MHTTracker(MHTConfig(scale_caps=scale), KnownClutter(40 / 8000.0**2)),
                  PlotTable.from_scans(scans)) for scale in (True, False)]
    assert not runs[0].caps and not runs[1].caps
    _same_tracks(runs[0].tracks, runs[1].tracks)


def test_scene_leaves_hand_worked():
    # 44 plots, 7 confirmed tracks: 16·44 + 50·7; a burst counts BURST_PLOTS plots
    assert scene_leaves(MHTConfig(), 44, 7) == 16 * 44 + 50 * 7 == 1054
    assert (LEAVES_PER_PLOT, LEAVES_PER_TRACK) == (16, 50)
    assert scene_leaves(MHTConfig(), 10**6, 0) == scene_leaves(MHTConfig(), 20_000, 0)
    assert scene_leaves(MHTConfig(scale_caps=False), 44, 7) is None


def test_a_leaf_cap_within_the_scene_budget_cuts_the_tentative_trees_only():
    """A per-tree cap that acts while the children stay below 16·n + 50·t (as in the
    1 000-target scene; here 10 clutter plots per scan): the rule cuts the tentative
    trees' children only (``max_tentative_per_plot``), never the full rule's
    ``max_leaves_per_plot``; with ``scale_caps`` off neither acts."""
    scans = _scene_scans(10, 12, 5)
    runs = [track(MHTTracker(MHTConfig(max_leaves_per_tree=3, scale_caps=scale),
                             KnownClutter(10 / 8000.0**2)), PlotTable.from_scans(scans))
            for scale in (True, False)]
    assert runs[0].caps.get("max_tentative_per_plot", 0) > 0
    assert "max_leaves_per_plot" not in runs[0].caps
    assert set(runs[1].caps) - {"scans"} == {"max_leaves_per_tree"}


@given(sizes=st.lists(st.integers(0, 30), min_size=0, max_size=12),
       n_plots=st.integers(1, 8), seed=st.integers(0, 2**32 - 1),
       per_plot=st.integers(1, 5), per_miss=st.integers(1, 3))
def test_cap_per_plot_among_a_subset_is_the_rule_on_that_subset(sizes, n_plots, seed,
                                                                per_plot, per_miss):
    """``among``: the brute force on the masked children alone; the others all kept."""
    tree, plot, score = _children(sizes, n_plots, seed)
    among = np.random.default_rng(seed).random(tree.size) < 0.6
    keep, cut = cap_per_plot(tree, plot, score, per_plot, per_miss, among=among)
    sub = np.flatnonzero(among)
    ref = np.ones(tree.size, bool)
    ref[sub] = _reference_keep(tree[sub], plot[sub], score[sub], per_plot, per_miss)
    np.testing.assert_array_equal(keep, ref)
    assert cut == tree.size - keep.sum()


def _prune_case(n_conf: int, n_tent: int, seed: int):
    """Leaves of one confirmed tree (``n_conf`` leaves) and one tentative tree
    (``n_tent``), each leaf with a miss and children on plots 0–2."""
    from dataclasses import replace

    from leaves_fixture import random_leaves

    from mhtrack.mht.extend import Children

    rng = np.random.default_rng(seed)
    n = n_conf + n_tent
    tree = np.r_[np.zeros(n_conf, np.int64), np.ones(n_tent, np.int64)]
    lv = random_leaves(rng, n, tree)
    lv = replace(lv, track=np.where(tree == 0, 7, -1), score=np.zeros(n),
                 peak=np.zeros(n))
    parent = np.repeat(np.arange(n), 4)
    plot = np.tile(np.array([-1, 0, 1, 2]), n)
    score = rng.normal(0, 0.1, parent.size)
    return lv, Children(parent, plot, score, score, np.arange(parent.size))


@pytest.mark.parametrize("seed", range(3))
def test_prune_children_picks_the_rule_by_the_scene_budget(seed):
    """Within the scene's budget the rule spares the confirmed tree; over it, it cuts
    every tree (``scene_leaves`` the children less births must exceed)."""
    from frame_fixture import frame

    from mhtrack.mht.pruning import prune_children
    from mhtrack.mht.sprt import SPRT

    lv, ch = _prune_case(6, 6, seed)
    cfg = MHTConfig(max_leaves_per_tree=20)  # each tree has 24 children: the cap acts
    sprt = SPRT.from_config(cfg)
    for budget, name in ((10**6, "max_tentative_per_plot"), (10, "max_leaves_per_plot")):
        f = frame(max_leaves_per_tree=20, scene_leaves=budget)
        out = prune_children(f, lv, ch, sprt, n_births=0)
        caps = f.caps
        assert set(caps) == {name, "max_leaves_per_tree"} or set(caps) == {name}
        conf = lv.track[out.parent] >= 0
        if name == "max_tentative_per_plot":  # the confirmed tree: only the per-tree cap
            assert conf.sum() == 20
            assert (~conf).sum() == 3 * CHILDREN_PER_PLOT + MISSES_PER_TREE
        else:
            assert out.parent.size == 3 * CHILDREN_PER_PLOT + 2 * MISSES_PER_TREE
