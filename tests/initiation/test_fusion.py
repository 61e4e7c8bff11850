"""Plot fusion (P2 §1): adaptive and standard K-means fusion, the one-plot-per-radar rule,
fused plots."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.initiation import (
    FUSED,
    AdaptiveKMeansFusion,
    KMeansFusion,
    fuse_clusters,
    majority_origin,
    split_inconsistent,
)
from mhtrack.records import Scan
from mhtrack.scenario import preset, simulate


def triplets(rng, n_targets=10, sigma=10.0, spacing=1000.0):
    """``n_targets`` targets on a grid, one plot per radar (ids 1–3) each."""
    g = np.arange(n_targets)
    truth = np.column_stack((g % 5, g // 5)) * spacing
    z = np.repeat(truth, 3, axis=0) + rng.normal(scale=sigma, size=(3 * n_targets, 2))
    sensor = np.tile([1, 2, 3], n_targets)
    origin = np.repeat(g, 3)
    perm = rng.permutation(len(z))
    return truth, z[perm], sensor[perm], origin[perm]


def test_adaptive_finds_ten_well_separated_triplets():
    rng = np.random.default_rng(3)
    sigma = 10.0
    truth, z, sensor, origin = triplets(rng, sigma=sigma)
    f = AdaptiveKMeansFusion(merge_probability=None, max_threshold=None).fit(z, sensor)
    assert f.n_clusters_ == 10
    # the partition is exactly the targets: one label per origin
    assert len({(a, b) for a, b in zip(f.labels_, origin, strict=True)}) == 10
    for lab in range(10):
        members = f.labels_ == lab
        np.testing.assert_allclose(f.cluster_centers_[lab], z[members].mean(axis=0))
        target = truth[origin[members][0]]
        # the mean of 3 plots has σ/√3 per axis: within 3 of its standard deviations
        assert np.hypot(*(f.cluster_centers_[lab] - target)) < 3 * sigma / np.sqrt(3)


def _check_one_plot_per_radar(labels, sensor):
    pairs = np.column_stack((labels, sensor))
    assert len(np.unique(pairs, axis=0)) == len(pairs), "a cluster holds two plots of a radar"


plot_sets = st.integers(2, 4).flatmap(
    lambda ns: st.tuples(
        st.just(ns),
        st.lists(st.integers(0, 7), min_size=ns, max_size=ns),
        st.integers(0, 2**32 - 1),
        st.floats(50.0, 3000.0),
    )
)


@settings(max_examples=60, deadline=None)
@given(plot_sets)
def test_one_plot_per_radar_always_holds(case):
    ns, counts, seed, box = case
    rng = np.random.default_rng(seed)
    sensor = np.repeat(np.arange(ns), counts)
    z = rng.uniform(0, box, size=(len(sensor), 2))
    R = np.broadcast_to(np.diag([400.0, 2500.0]), (len(z), 2, 2)).copy()
    fits = [
        AdaptiveKMeansFusion().fit(z, sensor, R),
        AdaptiveKMeansFusion(merge_probability=None, max_threshold=None).fit(z, sensor),
        KMeansFusion(max(1, int(np.max(counts))), random_state=seed).fit(z, sensor),
    ]
    for f in fits:
        assert len(f.labels_) == len(z)
        if len(z):
            assert set(f.labels_.tolist()) == set(range(f.n_clusters_))
        _check_one_plot_per_radar(f.labels_, sensor)


def test_fused_plots_mean_and_information_weighting():
    z = np.array([[0.0, 0.0], [3.0, 3.0], [50.0, 50.0]])
    R = np.array([np.diag([1.0, 4.0]), np.diag([2.0, 4.0]), np.diag([9.0, 9.0])])
    labels = np.array([0, 0, 1])
    zm, Rm = fuse_clusters(z, labels, R, weighting="mean")
    np.testing.assert_allclose(zm, [[1.5, 1.5], [50.0, 50.0]])
    np.testing.assert_allclose(Rm[0], np.diag([0.75, 2.0]))  # (R1 + R2) / 4
    zi, Ri = fuse_clusters(z, labels, R, weighting="information")
    # P = (R1⁻¹ + R2⁻¹)⁻¹ = diag(2/3, 2), z = P (R1⁻¹ z1 + R2⁻¹ z2) = (1, 1.5)
    np.testing.assert_allclose(Ri[0], np.diag([2 / 3, 2.0]))
    np.testing.assert_allclose(zi[0], [1.0, 1.5])
    np.testing.assert_array_equal(zi[1], z[2])  # a one-plot cluster is the plot itself
    np.testing.assert_array_equal(Ri[1], R[2])


def test_majority_origin():
    labels = np.array([0, 0, 0, 1, 1, 2, 2, 2, 3, 3])
    origin = np.array([5, 5, -1, 7, -1, -1, -1, 4, 9, 8])
    # 0: target 5 (2 vs 1 clutter); 1: tie target/clutter → target; 2: clutter-dominated;
    # 3: tie between targets → lower id
    np.testing.assert_array_equal(majority_origin(origin, labels, 4), [5, 7, -1, 8])


def test_fuse_scan_output():
    rng = np.random.default_rng(0)
    _, z, sensor, origin = triplets(rng, n_targets=4)
    z = np.vstack((z, [[9000.0, 9000.0]]))
    sensor = np.append(sensor, 2)
    origin = np.append(origin, -1)
    R = np.broadcast_to(np.eye(2) * 100.0, (len(z), 2, 2)).copy()
    scan = Scan(3, 3.0, z, sensor, np.arange(len(z)), R, origin)
    f = AdaptiveKMeansFusion().fuse(scan)
    assert f.n_clusters == 5
    lone = f.labels[-1]
    assert f.scan.sensor[lone] == 2 and f.scan.origin[lone] == -1  # left as it was
    np.testing.assert_array_equal(f.scan.z[lone], z[-1])
    others = np.setdiff1d(np.arange(5), [lone])
    assert (f.scan.sensor[others] == FUSED).all()
    assert sorted(f.scan.origin[others].tolist()) == [0, 1, 2, 3]
    assert f.scan.index == 3 and f.scan.R.shape == (5, 2, 2)


def test_random_kmeans_is_seeded():
    rng = np.random.default_rng(1)
    _, z, sensor, _ = triplets(rng)
    a = KMeansFusion(10, random_state=5).fit(z, sensor).labels_
    b = KMeansFusion(10, random_state=5).fit(z, sensor).labels_
    np.testing.assert_array_equal(a, b)


def test_multiradar_scan_without_clutter_gives_ten_clusters():
    sim = simulate(preset("multiradar", clutter_rate=0, scans=3), seed=4)
    for scan in sim.plots.scans():
        f = AdaptiveKMeansFusion().fuse(scan)
        assert f.n_clusters == 10
        assert sorted(f.scan.origin.tolist()) == list(range(1, 11))


def test_bad_parameters_are_rejected():
    z = np.zeros((3, 2))
    with pytest.raises(ValueError, match="weighting"):
        AdaptiveKMeansFusion(weighting="median").fit(z)
    with pytest.raises(ValueError, match="merge_probability"):
        AdaptiveKMeansFusion(merge_probability=1.5).fit(z)
    with pytest.raises(ValueError, match="n_clusters"):
        KMeansFusion(0).fit(z)
    with pytest.raises(ValueError, match="shape"):
        AdaptiveKMeansFusion().fit(np.zeros((3, 3)))


def test_information_weighting_without_covariances_is_the_plain_centre():
    z = np.array([[0.0, 0.0], [2.0, 4.0], [10.0, 10.0]])
    labels = np.array([0, 0, 1])
    zi, Ri = fuse_clusters(z, labels, None, weighting="information")
    assert Ri is None
    np.testing.assert_array_equal(zi, [[1.0, 2.0], [10.0, 10.0]])


def test_split_inconsistent_hand_cases():
    from scipy.stats import chi2

    R = np.tile(np.eye(2) * 50.0**2, (5, 1, 1))
    # two plots 500 m apart with σ = 50 m: T = 500²/(2·50²) = 50 > χ²₂(0.9999) ≈ 18.4
    z = np.array([[0.0, 0.0], [500.0, 0.0], [1000.0, 0.0], [1050.0, 0.0], [2000.0, 0.0]])
    labels = np.array([0, 0, 1, 1, 2])
    out = split_inconsistent(z, R, labels, 0.9999)
    assert out[0] != out[1]  # 500 m apart: split
    assert out[2] == out[3]  # 50 m apart: T = 0.5, kept
    assert len(np.unique(out)) == 4
    # the threshold is the χ²_{2(n-1)} quantile: a pair at T just below it stays together
    d = np.sqrt(2 * 50.0**2 * chi2.ppf(0.9999, 2)) * 0.999
    keep = split_inconsistent(np.array([[0.0, 0.0], [d, 0.0]]), R[:2], np.zeros(2, np.int64),
                              0.9999)
    assert keep[0] == keep[1]


def test_split_inconsistent_drops_the_outlier_of_three():
    R = np.array([np.diag([20.0**2, 80.0**2])] * 3)
    z = np.array([[0.0, 0.0], [10.0, 60.0], [400.0, 0.0]])  # the third is 20 σ off in x
    out = split_inconsistent(z, R, np.zeros(3, np.int64), 0.9999)
    assert out[0] == out[1] and out[2] != out[0]


@given(st.integers(0, 2**31 - 1))
@settings(max_examples=40, deadline=None)
def test_split_inconsistent_leaves_only_consistent_clusters(seed):
    from scipy.stats import chi2

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 12))
    z = rng.uniform(-300, 300, (n, 2))
    A = rng.normal(0, 40, (n, 2, 2))
    R = A @ np.swapaxes(A, 1, 2) + np.eye(2) * 100.0
    labels = rng.integers(0, 3, n)
    out = split_inconsistent(z, R, labels, 0.999)
    # a split only ever separates plots that were together
    assert all(len(np.unique(labels[out == c])) == 1 for c in np.unique(out))
    for c in np.unique(out):
        i = np.flatnonzero(out == c)
        if len(i) < 2:
            continue
        W = np.linalg.inv(R[i])
        zh = np.linalg.solve(W.sum(0), np.einsum("nij,nj->i", W, z[i]))
        d = z[i] - zh
        assert np.einsum("ni,nij,nj->", d, W, d) <= chi2.ppf(0.999, 2 * (len(i) - 1)) + 1e-9


@settings(max_examples=40, deadline=None)
@given(plot_sets)
def test_paper_fusion_is_p2_steps_only(case):
    """``AdaptiveKMeansFusion.paper()`` = P2 §1.2's initial centres with the Euclidean
    ε(k) then Lloyd, nothing after: same labels as composing the two steps by hand; and
    ``gate=False`` equals switching the gate's two parameters off."""
    from mhtrack.initiation.kmeans import adaptive_initial_centres, kmeans_lloyd

    ns, counts, seed, box = case
    rng = np.random.default_rng(seed)
    sensor = np.repeat(np.arange(ns), counts)
    z = rng.uniform(0, box, size=(len(sensor), 2))
    R = np.broadcast_to(np.diag([400.0, 2500.0]), (len(z), 2, 2)).copy()
    f = AdaptiveKMeansFusion.paper().fit(z, sensor, R)
    if len(z):
        c0, _, eps = adaptive_initial_centres(z, sensor)
        _, labels, _ = kmeans_lloyd(z, c0)
        np.testing.assert_array_equal(f.labels_, labels)
        assert f.threshold_ == eps
    a = AdaptiveKMeansFusion(gate=False).fit(z, sensor, R)
    b = AdaptiveKMeansFusion(merge_probability=None, max_threshold=None).fit(z, sensor)
    np.testing.assert_array_equal(a.labels_, b.labels_)


def test_paper_fusion_may_break_one_plot_per_radar_and_best_does_not():
    # radar 1 (3 plots, placed first) opens centres at 33, 79, 30; radar 0's 75 joins 79
    # and 54 joins a centre; Lloyd then moves 54 alone and puts radar 1's 30 and 33 in
    # one cluster — P2's steps keep it, our repair (best) splits it
    z = np.array([[75.0, 0.0], [54.0, 0.0], [33.0, 0.0], [79.0, 0.0], [30.0, 0.0]])
    sensor = np.array([0, 0, 1, 1, 1])
    paper = AdaptiveKMeansFusion.paper().fit(z, sensor)
    best = AdaptiveKMeansFusion().fit(z, sensor)
    _check_one_plot_per_radar(best.labels_, sensor)
    assert paper.labels_[2] == paper.labels_[4]  # 33 and 30, both radar 1
