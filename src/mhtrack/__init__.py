"""mhtrack — multiple-target tracking in unknown, varying clutter.

Layers (data flows one way; no module imports a later layer):
``records``/``errors``/``io`` → ``models`` → ``scenario``, ``clutter`` → ``mht``,
``initiation`` → ``build`` (the tracker builder) → ``metrics`` → ``experiments`` →
``plotting``, ``reports`` → ``cli``. ``names`` (every part's name list) imports nothing.
"""

from mhtrack.records import PlotTable, Scan, TrackTable, TruthTable

__version__ = "0.1.0"
__all__ = ["PlotTable", "Scan", "TrackTable", "TruthTable", "__version__"]
