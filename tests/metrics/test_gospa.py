"""GOSPA (α = 2) against hand-worked values, Stone Soup, and the metric axioms."""

import datetime
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from mhtrack.metrics import GOSPAResult, gospa, gospa_per_scan

# ---------------------------------------------------------------- hand-worked examples


def test_two_truths_one_track_hand_worked():
    # X (truth) = {(0,0), (100,0)}, Y = {(0,30)}, c = 50, p = 2: pair (0,0)–(0,30) at 30 m;
    # (100,0) is missed. GOSPA² = 30² + 50²/2 · 1 = 900 + 1250.
    r = gospa([[0, 0], [100, 0]], [[0, 30]], c=50, p=2)
    assert r.distance == pytest.approx(math.sqrt(2150))
    assert (r.localisation, r.missed, r.false) == pytest.approx((30, math.sqrt(1250), 0))
    assert (r.n_assigned, r.n_missed, r.n_false) == (1, 1, 0)
    # the same with roles swapped: the unpaired point is now a false estimate
    s = gospa([[0, 30]], [[0, 0], [100, 0]], c=50, p=2)
    assert s.distance == pytest.approx(r.distance)
    assert (s.n_missed, s.n_false) == (0, 1)


def test_pair_beyond_cutoff_is_one_missed_one_false():
    # 80 m apart with c = 50: assigning would cost 50^p = 2 · 50^p/2 — reported unassigned
    r = gospa([[0, 0]], [[0, 80]], c=50, p=1)
    assert r.distance == pytest.approx(50)
    assert (r.n_assigned, r.n_missed, r.n_false) == (0, 1, 1)
    assert (r.localisation, r.missed, r.false) == pytest.approx((0, 25, 25))


def test_grows_with_number_of_errors_unlike_ospa():
    # k missed targets and nothing else: GOSPA = (k · c^p/2)^(1/p)
    for k in range(1, 5):
        X = np.column_stack((np.arange(k) * 1000.0, np.zeros(k)))
        assert gospa(X, [], c=100, p=2).distance == pytest.approx(100 * math.sqrt(k / 2))


def test_both_empty():
    assert gospa([], [], 10, 2) == GOSPAResult(0.0, 0.0, 0.0, 0.0, 0, 0, 0)


def test_invalid_parameters():
    with pytest.raises(ValueError, match="c must be"):
        gospa([[0, 0]], [[0, 0]], c=-5, p=2)
    with pytest.raises(ValueError, match="p must be"):
        gospa([[0, 0]], [[0, 0]], c=5, p=0)


def test_per_scan(make_truth, make_tracks):
    truth = make_truth([(0, 1, 0, 0), (0, 2, 100, 0), (1, 1, 0, 0)])
    tracks = make_tracks([(0, 7, 0, 30), (2, 7, 0, 0)])
    r = gospa_per_scan(tracks, truth, 50, 2, scans=[3])
    assert r.scan.tolist() == [0, 1, 2, 3]
    # scan 0: hand-worked above; 1: one missed; 2: one false; 3: empty
    h = 50 / math.sqrt(2)
    assert r.distance == pytest.approx([math.sqrt(2150), h, h, 0])
    assert r.n_missed.tolist() == [1, 1, 0, 0]
    assert r.n_false.tolist() == [0, 0, 1, 0]


# ---------------------------------------------------------------- Stone Soup reference

X_FIXED = np.array([[0.0, 0.0], [120.0, 40.0], [400.0, -80.0], [410.0, 260.0], [-300.0, 150.0]])
Y_FIXED = np.array([[25.0, -10.0], [150.0, 90.0], [395.0, 175.0], [900.0, 900.0]])
# Frozen with stonesoup 1.9.1 (numpy 2.4.6, scipy 1.17.1):
#   g, _ = GOSPAMetric(c=300.0, p=2.0).compute_gospa_metric(states(Y_FIXED), states(X_FIXED))
#   g.value -> {'distance': 382.8511460084716, 'localisation': 11575.0,
#               'missed': 90000.0, 'false': 45000.0}
# (Stone Soup's components are p-th powers; ours are their p-th roots.) By hand: three
# pairs with d² = 725 + 3400 + 7450 = 11575, two missed truths, one false estimate:
# GOSPA² = 11575 + 300²/2 · 3.
SS_GOSPA_FIXED = (382.8511460084716, 11575.0, 90000.0, 45000.0)


def test_fixed_example_frozen_reference():
    r = gospa(X_FIXED, Y_FIXED, 300, 2)
    assert r.distance == pytest.approx(math.sqrt(11575 + 45000 * 3))
    assert (r.distance, r.localisation**2, r.missed**2, r.false**2) == pytest.approx(
        SS_GOSPA_FIXED, rel=1e-12
    )
    assert (r.n_assigned, r.n_missed, r.n_false) == (3, 2, 1)


def test_against_stonesoup_live():
    ospametric = pytest.importorskip("stonesoup.metricgenerator.ospametric")
    state = pytest.importorskip("stonesoup.types.state")
    t = datetime.datetime(2024, 1, 1)

    def states(P):
        return [state.State(np.reshape(q, (2, 1)), timestamp=t) for q in P]

    rng = np.random.default_rng(99)
    for _ in range(60):
        X = rng.uniform(0, 800, (rng.integers(0, 7), 2))
        Y = rng.uniform(0, 800, (rng.integers(0, 7), 2))
        if len(X) + len(Y) == 0:
            continue
        c, p = rng.choice([100.0, 250.0]), rng.choice([1.0, 2.0, 3.0])
        g, _ = ospametric.GOSPAMetric(c=c, p=p).compute_gospa_metric(states(Y), states(X))
        mine = gospa(X, Y, c, p)
        ref = g.value
        assert mine.distance == pytest.approx(ref["distance"], rel=1e-9, abs=1e-9)
        assert mine.localisation**p == pytest.approx(ref["localisation"], rel=1e-9, abs=1e-6)
        assert mine.missed**p == pytest.approx(ref["missed"], rel=1e-9, abs=1e-6)
        assert mine.false**p == pytest.approx(ref["false"], rel=1e-9, abs=1e-6)


# ---------------------------------------------------------------- properties

coords = st.floats(-1000, 1000, allow_nan=False, allow_infinity=False)


def point_sets(max_size=4):
    return st.integers(0, max_size).flatmap(lambda n: arrays(np.float64, (n, 2), elements=coords))


params = st.tuples(st.floats(1.0, 2000.0), st.sampled_from([1.0, 2.0, 3.0]))


@settings(max_examples=150, deadline=None)
@given(point_sets(), point_sets(), params)
def test_symmetric_and_decomposed(X, Y, cp):
    c, p = cp
    a, b = gospa(X, Y, c, p), gospa(Y, X, c, p)
    assert a.distance == pytest.approx(b.distance, rel=1e-9, abs=1e-9)
    assert (a.n_missed, a.n_false) == (b.n_false, b.n_missed)
    assert a.n_assigned + a.n_missed == len(X) and a.n_assigned + a.n_false == len(Y)
    total = a.localisation**p + a.missed**p + a.false**p
    assert a.distance**p == pytest.approx(total, rel=1e-9, abs=1e-9)


@settings(max_examples=150, deadline=None)
@given(point_sets(3), point_sets(3), point_sets(3), params)
def test_triangle_inequality(X, Y, Z, cp):
    c, p = cp
    assert gospa(X, Z, c, p).distance <= (
        gospa(X, Y, c, p).distance + gospa(Y, Z, c, p).distance + 1e-7 * c
    )
    assert gospa(X, X, c, p).distance == pytest.approx(0.0, abs=1e-9)


@settings(max_examples=100, deadline=None)
@given(point_sets(5), point_sets(5), params, st.randoms(use_true_random=False))
def test_invariant_to_row_order(X, Y, cp, rnd):
    px, py = list(range(len(X))), list(range(len(Y)))
    rnd.shuffle(px)
    rnd.shuffle(py)
    a, b = gospa(X[px], Y[py], *cp), gospa(X, Y, *cp)
    assert a.distance == pytest.approx(b.distance, rel=1e-9, abs=1e-9)
