"""Clutter estimators by name: ``known``, ``gmm``, ``agmm``."""

from __future__ import annotations

from typing import Any

from mhtrack.clutter.agmm import AGMMClutter
from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.gmm import GMMClutter
from mhtrack.clutter.known import KnownClutter

#: Estimator name → class.
ESTIMATORS: dict[str, type] = {"known": KnownClutter, "gmm": GMMClutter, "agmm": AGMMClutter}


def make_estimator(name: str, *, kappa: float | None = None, **params: Any) -> ClutterEstimator:
    """A fresh estimator by name. ``kappa`` is the constant of ``known`` (default 1e−9
    per m², P1's plain MHT); ``params`` go to the mixture estimators' constructors
    (``None`` values are left at their defaults)."""
    if name not in ESTIMATORS:
        raise ValueError(f"unknown clutter estimator {name!r} (expected {', '.join(ESTIMATORS)})")
    if name == "known":
        return KnownClutter() if kappa is None else KnownClutter(kappa)
    return ESTIMATORS[name](**{k: v for k, v in params.items() if v is not None})


def gmm_for_tracker(config: Any = None, clutter_density: float | None = None) -> GMMClutter:
    """MHT-GMM's clutter estimator (``TRACKERS["mht-gmm"]``): :class:`GMMClutter` with its
    defaults, fed all plots (``source="all"``; ``docs/clutter.md`` says why not
    ``"outside-gates"``). ``config`` and ``clutter_density`` are not used."""
    return GMMClutter()


def agmm_for_tracker(config: Any = None, clutter_density: float | None = None) -> AGMMClutter:
    """MHT-AGMM's clutter estimator (``TRACKERS["mht-agmm"]``): :class:`AGMMClutter` with
    its defaults, fed all plots. ``config`` and ``clutter_density`` are not used."""
    return AGMMClutter()
