"""One-time code loaded when a live run starts, not in the middle of it (``docs/live.md``,
*Soak*).

The tracker imports some of its code at the first frame that needs it: SciPy's
``milp`` for a cluster the branch-and-bound gives up on (``mht/hypothesis.py``), its
sparse graphs, spatial trees and distributions, and numba's compiled IMM rows for a
store of :data:`~mhtrack.models.imm_rows.MIN_ROWS` rows. Each is loaded once and kept:
the process's resident memory steps up by its size (measured: SciPy's optimiser and
sparse matrices on the code of the first soak +33 MB; numba and the compiled rows
+131 MB, 2.7 s from numba's cache, 31 s compiling on a loaded machine) in whichever
hour first needs it — the soak's step of +26 % between hour 1 and hour 2 — and the
frame that needs it waits. A service loads it at start: :func:`preload`.
"""

from __future__ import annotations

import importlib
import sys

#: Modules the tracker imports inside functions (``grep -rn "^\s+from scipy"``).
LAZY_MODULES = ("scipy.optimize", "scipy.sparse", "scipy.sparse.csgraph",
                "scipy.spatial", "scipy.spatial.distance", "scipy.stats")


def preload() -> tuple[int, bool]:
    """Import :data:`LAZY_MODULES`, load the compiled IMM rows
    (:func:`mhtrack.models.imm_preload.preload`) and the clutter map's compiled quadrature
    (:func:`mhtrack.clutter.cell_mass.preload`); the number of modules this added and
    whether the compiled rows are in use."""
    from mhtrack.clutter.cell_mass import preload as quadrature
    from mhtrack.models.imm_preload import preload as compiled

    before = len(sys.modules)
    for name in LAZY_MODULES:
        importlib.import_module(name)
    used = compiled()
    quadrature()
    return len(sys.modules) - before, used
