"""Clutter estimators by name — transitional.

The names are :data:`mhtrack.names.CLUTTER_ESTIMATORS`, the name → class mapping and the
factory :func:`mhtrack.build.make_clutter_estimator`. This module stays only until
``clutter/__init__.py`` and ``tests/clutter/test_estimators.py`` import those (issue 13
merge; then delete it).
"""

from __future__ import annotations

from typing import Any

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.names import CLUTTER_ESTIMATORS as ESTIMATORS


def make_estimator(name: str, *, kappa: float | None = None, **params: Any) -> ClutterEstimator:
    """:func:`mhtrack.build.make_clutter_estimator` (transitional, see above)."""
    from mhtrack.build import make_clutter_estimator

    return make_clutter_estimator(name, kappa=kappa, **params)


__all__ = ["ESTIMATORS", "make_estimator"]
