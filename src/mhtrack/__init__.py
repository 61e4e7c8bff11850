"""mhtrack — multiple-target tracking in unknown, varying clutter.

The layers of the package (data flows one way) are in ``docs/architecture.md``,
*Layers*, and checked by ``tests/test_layers.py``.

The tables (``PlotTable``, ``Scan``, ``TrackTable``, ``TruthTable``) are imported from
:mod:`mhtrack.records` on first use (PEP 562), so that ``import mhtrack`` — and
``mhtrack --help`` — do not load NumPy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from mhtrack.records import PlotTable, Scan, TrackTable, TruthTable

__version__ = "0.1.0"
__all__ = ["PlotTable", "Scan", "TrackTable", "TruthTable", "__version__"]


def __getattr__(name: str) -> Any:
    """The record tables, imported on first access."""
    if name in ("PlotTable", "Scan", "TrackTable", "TruthTable"):
        from mhtrack import records

        return getattr(records, name)
    raise AttributeError(f"module 'mhtrack' has no attribute {name!r}")
