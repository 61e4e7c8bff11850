"""``tree.filled`` is ``np.full``: same values, dtype and shape (empty included)."""

import numpy as np
import pytest

from mhtrack.mht.tree import filled


@pytest.mark.parametrize(("n", "value", "dtype"), [(0, -1, np.int64), (5, -1, np.int64),
                                                   (7, 3.5, float), (3, 12, np.int64),
                                                   (4, np.nan, float)])
def test_filled_is_np_full(n, value, dtype):
    got, want = filled(n, value, dtype), np.full(n, value, dtype)
    assert got.dtype == want.dtype and got.shape == want.shape
    assert got.tobytes() == want.tobytes()
