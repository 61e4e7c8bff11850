"""mhtrack — multiple-target tracking in unknown, varying clutter.

Layers (each a sub-package; none imports a later one):
``records``/``errors`` → ``models`` → ``scenario`` → ``clutter`` → ``mht`` →
``initiation`` → ``metrics`` → ``io`` → ``experiments`` → ``plotting`` → ``cli``.
"""

from mhtrack.records import PlotTable, Scan, TrackTable, TruthTable

__version__ = "0.1.0"
__all__ = ["PlotTable", "Scan", "TrackTable", "TruthTable", "__version__"]
