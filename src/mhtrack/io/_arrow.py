"""Fixed-width pyarrow columns to and from NumPy through their buffers.

pyarrow's own ``to_numpy``, ``pa.array`` and ``pa.scalar`` import pandas (0.2 s, most of a
small ``mhtrack track``'s start-up; issue 18). The Arrow layout is fixed — a validity
bitmap (LSB first) and a contiguous data buffer per chunk — so the same values are read
and written here directly (Arrow columnar format, "Fixed-size primitive layout").
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa

_DTYPES = {pa.int64(): np.int64, pa.float64(): np.float64}


def _bits(buf: pa.Buffer, offset: int, n: int) -> np.ndarray:
    """Bits ``offset … offset+n-1`` of an Arrow bitmap (least significant bit first)."""
    bits = np.unpackbits(np.frombuffer(buf, np.uint8), bitorder="little")
    return bits[offset : offset + n].astype(bool)


def _chunk(a: pa.Array) -> np.ndarray:
    if a.null_count == len(a) or a.buffers()[1] is None:  # all null: no data buffer needed
        return np.zeros(len(a), _DTYPES.get(a.type, bool))
    if a.type == pa.bool_():
        return _bits(a.buffers()[1], a.offset, len(a))
    dtype = _DTYPES[a.type]
    return np.frombuffer(a.buffers()[1], dtype, count=len(a), offset=a.offset * 8)


def to_numpy(col: pa.ChunkedArray | pa.Array, fill: float | int | bool = 0) -> np.ndarray:
    """A writable copy of an int64, float64 or boolean column; null cells become ``fill``
    (their data slots are undefined in Arrow)."""
    chunks = col.chunks if isinstance(col, pa.ChunkedArray) else [col]
    if not chunks:
        return np.zeros(0, _DTYPES.get(col.type, bool))
    v = np.concatenate([_chunk(c) for c in chunks])  # always a copy
    if col.null_count:
        v[is_null(col)] = fill
    return v


def is_null(col: pa.ChunkedArray | pa.Array) -> np.ndarray:
    """Boolean mask of the null cells of ``col``."""
    if col.null_count == 0:
        return np.zeros(len(col), bool)
    chunks = col.chunks if isinstance(col, pa.ChunkedArray) else [col]
    return np.concatenate([
        np.full(len(c), c.null_count == len(c)) if c.buffers()[0] is None
        else ~_bits(c.buffers()[0], c.offset, len(c)) for c in chunks
    ])


def from_numpy(values: np.ndarray, type_: pa.DataType,
               missing: np.ndarray | None = None) -> pa.Array:
    """An int64 or float64 pyarrow array of ``values``; ``missing`` rows become nulls."""
    v = np.ascontiguousarray(values, _DTYPES[type_])
    validity, nulls = None, 0
    if missing is not None:
        missing = np.asarray(missing, bool)
        nulls = int(missing.sum())
        if nulls:
            validity = pa.py_buffer(np.packbits(~missing, bitorder="little"))
    return pa.Array.from_buffers(type_, len(v), [validity, pa.py_buffer(v)], null_count=nulls)
