"""The IMM's compiled row loops (:mod:`mhtrack.models.imm_rows`) loaded and compiled
now, not at the first store of :data:`~mhtrack.models.imm_rows.MIN_ROWS` rows
(``docs/live.md``, *Soak*).

A long-running service pays its one-time costs at start: numba's import and the loops'
compilation (or loading from numba's on-disk cache) take about 60 MB of resident memory
and seconds of CPU. Left to the first big store, they come in the middle of a run — in
the frame that first makes a big store, at a burst, when the feed can least wait — and
show as a step in the resident memory at that hour. :func:`preload` runs
:meth:`~mhtrack.models.imm.CVModelSet.predict`, :meth:`~mhtrack.models.imm.CVModelSet.update`
and :meth:`~mhtrack.models.imm.CVModelSet.children_states` once on a store of
``MIN_ROWS`` made-up rows: the calls the tracker makes, so the same compiled
signatures (every array is passed C-contiguous, float64 or int64; the prediction with
one time step for all rows and with one per row, whose mixing matrices have one
dimension more). Nothing is computed
for the tracker; the floats of later calls do not depend on it.
"""

from __future__ import annotations

import numpy as np

from mhtrack.models import imm_rows
from mhtrack.models.imm import CVModelSet
from mhtrack.models.motion import States


def preload() -> bool:
    """Load and compile the compiled loops now (module docstring); whether they are in
    use (``False``: numba absent or ``MHTRACK_COMPILED=0``, nothing loaded)."""
    M = imm_rows.MIN_ROWS
    if imm_rows.kernels(M) is None:
        return False
    r = 2
    model = CVModelSet((1.0, 20.0), 60.0)
    eye = np.broadcast_to(np.eye(4), (M, r, 4, 4))
    s = States(np.zeros((M, 4)), np.zeros((M, 4, 4)), np.zeros((M, r, 4)),
               100.0 * eye.copy(), np.full((M, r), 1.0 / r))
    model.predict(s, 1.0)  # one time step for all rows, and one per row
    pred = model.predict(s, np.ones(M))
    z, R = np.zeros((M, 2)), 100.0 * np.eye(2)
    rows = np.arange(M)
    _, posterior = model.gating_scores(pred, rows, rows, z, R, np.zeros(M))
    model.update(pred, z, R, posterior)
    model.children_states(pred, rows, rows, rows, z, R, posterior)
    return True
