"""``mhtrack.io._arrow`` against pyarrow's own conversions (the reference): the same
values for chunked, sliced, null-holding and all-null columns, both ways."""

import numpy as np
import pyarrow as pa
import pytest

from mhtrack.io._arrow import from_numpy, is_null, to_numpy

VALUES = {
    pa.int64(): [[3, None, -7, 2**62], [], [None, None], [5, 6, None, 8, 9]],
    pa.float64(): [[1.5, None, -0.0, np.inf], [None], [], [2.25, float("nan"), None, 1e300]],
}


def _columns(t: pa.DataType) -> list[pa.ChunkedArray | pa.Array]:
    whole = pa.chunked_array([pa.array(c, type=t) for c in VALUES[t]], type=t)
    flat = whole.combine_chunks()
    return [whole, flat, flat.slice(3), flat.slice(1, 5), whole.slice(2, 6),
            pa.chunked_array([], type=t), pa.nulls(4, t)]


@pytest.mark.parametrize("t", list(VALUES))
def test_to_numpy_and_is_null_equal_pyarrow(t: pa.DataType) -> None:
    fill = -1 if pa.types.is_integer(t) else np.nan
    for col in _columns(t):
        ref = col.fill_null(fill).to_numpy()
        mine = to_numpy(col, fill=fill)
        assert mine.dtype == ref.dtype and mine.flags.writeable
        np.testing.assert_array_equal(mine, ref)
        np.testing.assert_array_equal(is_null(col), col.is_null().to_numpy(zero_copy_only=False))


def test_booleans_read_bit_by_bit() -> None:
    col = pa.chunked_array([pa.array([True, False, True] * 5)]).slice(2, 11)
    np.testing.assert_array_equal(to_numpy(col), col.to_numpy())


@pytest.mark.parametrize("t", list(VALUES))
def test_from_numpy_equals_pa_array_with_mask(t: pa.DataType) -> None:
    v = np.array([4, 0, -3, 9, 1, 2, 7, 8, 5], t.to_pandas_dtype())
    for missing in (None, np.zeros(9, bool), np.arange(9) % 3 == 1, np.ones(9, bool)):
        assert from_numpy(v, t, missing).equals(pa.array(v, type=t, mask=missing))
