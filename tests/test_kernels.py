"""``mhtrack.kernels`` gives bit for bit what the plain form in each docstring gives."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from mhtrack.kernels import changes, cov_biased, max_, mean, same_floats, sum_


@given(st.lists(st.integers(-3, 3), max_size=40))
def test_changes_is_the_r_form(keys):
    k = np.sort(np.asarray(keys, np.int64))
    want = np.r_[True, k[1:] != k[:-1]] if k.size else np.zeros(0, bool)
    got = changes(k)
    assert got.dtype == want.dtype and np.array_equal(got, want)


def test_same_floats_compares_bits_and_shape():
    a = np.array([[0.0, np.nan], [1.5, -2.0]])
    assert same_floats(a, a.copy())  # a NaN equals itself, bit for bit
    assert not same_floats(a, np.where(a == 0.0, -0.0, a))  # -0.0 is not 0.0
    assert not same_floats(a, a.reshape(4, 1))
    assert not same_floats(a, a.astype(np.float32))
    b = a.copy()
    b[1, 1] = np.nextafter(-2.0, 0.0)
    assert not same_floats(a, b)


@given(st.lists(st.floats(-1e6, 1e6), min_size=1, max_size=300))
def test_mean_and_the_reductions_are_the_methods(values):
    a = np.asarray(values, float)
    assert np.float64(mean(a)).tobytes() == a.mean().tobytes()
    m = np.vstack([a, a[::-1]])
    assert sum_(m, axis=0).tobytes() == m.sum(axis=0).tobytes()
    assert sum_(a).tobytes() == a.sum().tobytes()
    assert max_(m, axis=1).tobytes() == m.max(axis=1).tobytes()


@given(st.lists(st.tuples(st.floats(-1e5, 1e5), st.floats(-1e5, 1e5)), min_size=2,
                max_size=60))
def test_cov_biased_is_np_cov(points):
    z = np.asarray(points, float)
    assert cov_biased(z).tobytes() == np.cov(z.T, bias=True).tobytes()
