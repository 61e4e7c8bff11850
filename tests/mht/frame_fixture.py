"""A :class:`~mhtrack.mht.context.FrameContext` for tests of one stage: plots ``z``
(default none), their covariances ``R``, row ids (default ``0 … n−1``), plot times ``t``,
the frame's ``time`` and its limits (``MHTConfig`` fields)."""

from __future__ import annotations

import dataclasses

import numpy as np

from mhtrack.mht.config import MHTConfig
from mhtrack.mht.context import FrameContext
from mhtrack.records import Scan


def frame(z: np.ndarray | None = None, R: np.ndarray | None = None, *,
          rows: np.ndarray | None = None, t: np.ndarray | None = None, time: float = 0.0,
          scene_leaves: int | None = None, **limits: int) -> FrameContext:
    z = np.zeros((0, 2)) if z is None else np.asarray(z, float)
    R = np.eye(2) * 1e4 if R is None else R
    rows = np.arange(len(z)) if rows is None else rows
    scan = Scan(0, float(time), z, np.zeros(len(z), np.int64), rows,
                None if R.ndim == 2 else R, None, t)
    return FrameContext(scan, z, R, rows, dataclasses.replace(MHTConfig(), **limits),
                        scene_leaves)
