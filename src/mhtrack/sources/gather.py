"""Columns gathered chunk by chunk over a whole pass (the survey of a recording: every
plot's ``x, y``, time and sensor; the sweep marks), in growing buffers of plain octets
(``array.array``, grown in place by a fraction of its size) rather than a list of small
arrays concatenated at the end: no copy of the whole at the end, and no small objects
left behind chunk after chunk among the pass's short-lived ones, which kept the memory
they were allocated among from being given back (peak RSS grew with the recording's
length; benchmarks/bench_memory.py).
"""

from __future__ import annotations

from array import array
from collections.abc import Iterable, Mapping

import numpy as np

#: ``array.array`` type codes of the dtypes gathered.
_CODES = {np.dtype(float): "d", np.dtype(np.int64): "q"}


class Gathered:
    """Named columns of dtypes ``float`` or ``int64``, appended to in chunks."""

    def __init__(self, dtypes: Mapping[str, type | np.dtype]) -> None:
        self.dtypes = {k: np.dtype(d) for k, d in dtypes.items()}
        self.buffers = {k: array(_CODES[d]) for k, d in self.dtypes.items()}

    def add(self, cols: Mapping[str, np.ndarray]) -> None:
        """Append a chunk (every column, each converted to its dtype)."""
        for k, buf in self.buffers.items():
            buf.frombytes(np.ascontiguousarray(cols[k], self.dtypes[k]).tobytes())

    def extend(self, rows: Iterable[tuple[float, ...]]) -> None:
        """Append rows, their values in the columns' order (as a list of rows would)."""
        for row in rows:
            for buf, v in zip(self.buffers.values(), row, strict=True):
                buf.append(v)

    def columns(self) -> dict[str, np.ndarray]:
        """The columns gathered (views of the buffers: gather nothing more after)."""
        return {k: np.frombuffer(buf, self.dtypes[k]) if len(buf) else
                np.zeros(0, self.dtypes[k]) for k, buf in self.buffers.items()}
