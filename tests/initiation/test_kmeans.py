"""Plot clustering (P2 §1): the adaptive threshold ``ε(k)``, Lloyd's K-means, the merge of
compatible clusters (the estimators and fused plots: ``test_fusion.py``)."""

import numpy as np
import pytest

from mhtrack.initiation import (
    Gate,
    dissimilarity_threshold,
    kmeans_lloyd,
    merge_compatible_clusters,
)


def test_threshold_indexing_is_one_based_and_clipped():
    D = np.arange(1.0, 11.0)  # sorted distances 1..10
    # N_s = 3 → C(3,2) = 3 pairs per cluster: ε(1) = D(3) (1-based) = 3, ε(2) = D(6) = 6
    assert dissimilarity_threshold(D, 1, 3) == 3.0
    assert dissimilarity_threshold(D, 2, 3) == 6.0
    assert dissimilarity_threshold(D, 50, 3) == 10.0  # clipped to the largest
    assert dissimilarity_threshold(D, 1, 2) == 1.0  # C(2,2) = 1
    assert dissimilarity_threshold(D, 4, 1) == 0.0  # one radar: nothing to fuse
    assert dissimilarity_threshold(np.zeros(0), 1, 3) == 0.0


@pytest.mark.parametrize("seed", [0, 1])
def test_lloyd_refinement_equals_sklearn(seed):
    KMeans = pytest.importorskip(  # the reference (dev extra), not a dependency
        "sklearn.cluster", reason="scikit-learn (dev extra) not installed").KMeans
    rng = np.random.default_rng(seed)
    means = rng.uniform(0, 1000, size=(6, 2))
    z = np.concatenate([m + rng.normal(scale=120.0, size=(15, 2)) for m in means])
    init = z[rng.choice(len(z), 6, replace=False)]
    centres, labels, n_iter = kmeans_lloyd(z, init)
    ref = KMeans(n_clusters=6, init=init, n_init=1, tol=0.0, algorithm="lloyd").fit(z)
    assert n_iter > 1  # the data make it iterate
    np.testing.assert_array_equal(labels, ref.labels_)
    np.testing.assert_allclose(centres, ref.cluster_centers_, rtol=0, atol=1e-9)


def test_merge_joins_compatible_clusters_only():
    z = np.array([[0.0, 0.0], [10.0, 0.0], [60.0, 0.0], [2000.0, 0.0], [2050.0, 0.0]])
    sensor = np.array([1, 2, 3, 1, 1])
    labels = np.array([0, 0, 1, 2, 3])
    out = merge_compatible_clusters(z, sensor, labels, Gate(100.0))
    assert out[0] == out[1] == out[2]  # {r1, r2} + {r3} at ~55 m: merged
    assert out[3] != out[4]  # two plots of radar 1, 50 m apart: never merged
    far = merge_compatible_clusters(z, sensor, labels, Gate(20.0))
    assert far[2] != far[0]  # beyond ε: kept apart
