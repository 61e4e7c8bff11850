"""GeographicLib's WGS-84 geodesic (Karney 2013), the independent reference of the
geodesy tests, from the ``dev`` extra.

``WGS84.Direct(...)`` / ``WGS84.Inverse(...)`` import GeographicLib when first called; a
test that calls them is skipped, with the reason, where it is not installed (the tour's
``pip install -e ".[asterix,report,stonesoup]"`` has no dev extra), so the module's other
tests still run. ``WGS84.FULL`` is ``Geodesic.STANDARD | Geodesic.REDUCEDLENGTH``.
"""

from __future__ import annotations

from typing import Any

import pytest

REASON = "geographiclib (the dev extra) not installed: pip install -e '.[dev]'"


def geodesic_class() -> Any:
    """``geographiclib.geodesic.Geodesic``, or skip the calling test."""
    return pytest.importorskip("geographiclib.geodesic", reason=REASON).Geodesic


class _WGS84:
    """``Geodesic.WGS84``, imported when first used."""

    def __getattr__(self, name: str) -> Any:
        g = geodesic_class()
        if name == "FULL":
            return g.STANDARD | g.REDUCEDLENGTH
        return getattr(g.WGS84, name)


WGS84 = _WGS84()
