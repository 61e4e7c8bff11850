"""Common parameter overrides of a scenario (what the CLI options change).

``apply_overrides(scenario, **overrides)`` returns a new scenario; ``None`` values are
ignored, so a CLI can pass unset options through. Overrides:

* ``clutter`` — ``"uniform"``: uniform clutter over the region with the rate of the first
  scan; ``"gmm"``: keep a mixture (or time-varying mixture) as it is, and replace uniform
  clutter by :func:`default_mixture` with the same rate;
* ``clutter_rate`` — mean clutter count per scan **per sensor** (``>= 0``; for time-varying
  clutter every keyframe gets this rate); a rate that would make the simulation exceed
  :data:`~mhtrack.scenario.limits.MAX_PLOTS` plots is refused with the message naming
  ``clutter.rate`` that a TOML file gets (the check is in :class:`Scenario`);
* ``pd`` — detection probability of every sensor;
* ``scans`` — number of scans from the first one, at most
  :data:`~mhtrack.scenario.limits.MAX_SCANS` (the targets are not changed: those
  outside the new range are simply not simulated);
* ``truth_sigma_v`` — truth acceleration noise σv (m/s²);
* ``sigma_range`` — range σ (m) of every polar sensor (error if there is none).

For rotating radars (their own clutter per rotation) ``clutter_rate`` is every radar's
uniform range–azimuth rate per rotation, and ``clutter`` is refused.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from mhtrack.models.clutter import (
    GaussianMixtureClutter,
    Region,
    TimeVaryingClutter,
    UniformClutter,
)
from mhtrack.models.sensors import MAX_SIGMA, PolarRadar, RotatingRadar
from mhtrack.scenario import _check as ck
from mhtrack.scenario.dictform import ClutterSpec
from mhtrack.scenario.limits import MAX_SCANS, MAX_SIGMA_V
from mhtrack.scenario.spec import Scenario

#: Overrides accepted by :func:`apply_overrides`.
OVERRIDES: tuple[str, ...] = (
    "clutter",
    "clutter_rate",
    "pd",
    "scans",
    "truth_sigma_v",
    "sigma_range",
)


def default_mixture(region: Region, rate: float) -> GaussianMixtureClutter:
    """Mixture used by ``clutter="gmm"`` when the clutter is uniform (our choice): four
    equal-weight components at the region's centre ``± (w/4, h/4)``, covariance
    ``diag((w/10)², (h/10)²)`` (``w``, ``h`` the region's width and height), no background."""
    w, h = region.xmax - region.xmin, region.ymax - region.ymin
    c = np.array([(region.xmin + region.xmax) / 2, (region.ymin + region.ymax) / 2])
    offs = np.array([(-1, -1), (1, -1), (-1, 1), (1, 1)]) * np.array([w / 4, h / 4])
    cov = np.diag([(w / 10) ** 2, (h / 10) ** 2])
    return GaussianMixtureClutter(region, rate, np.full(4, 0.25), c + offs, np.stack([cov] * 4))


def check_override_names(overrides: Mapping[str, Any], allowed: Iterable[str]) -> None:
    """Raise ``ValueError`` naming every unknown override."""
    allowed = tuple(allowed)
    unknown = sorted(set(overrides) - set(allowed))
    if unknown:
        raise ValueError(
            f"unknown override{'s' if len(unknown) > 1 else ''} "
            f"{', '.join(map(repr, unknown))} (expected {', '.join(allowed)})"
        )


def _with_rate(c: ClutterSpec, rate: float) -> ClutterSpec:
    if isinstance(c, TimeVaryingClutter):
        return TimeVaryingClutter(
            tuple((k, dataclasses.replace(m, rate_per_scan=rate)) for k, m in c.keyframes)
        )
    return dataclasses.replace(c, rate_per_scan=rate)


def apply_overrides(scenario: Scenario, **overrides: Any) -> Scenario:
    """``scenario`` with the overrides of the module docstring applied.

    Raises ``ValueError`` naming the override for an unknown name or a bad value.
    """
    ov = {k: v for k, v in overrides.items() if v is not None}
    check_override_names(ov, OVERRIDES)
    s = scenario
    changes: dict[str, Any] = {}
    clutter = s.clutter
    if s.rotating and ("clutter" in ov or "clutter_rate" in ov):
        if "clutter" in ov:
            raise ValueError("clutter: rotating radars draw their own clutter in range and "
                             "azimuth; only clutter_rate (per rotation) can be changed")
        rate = ck.number(ov.pop("clutter_rate"), "clutter_rate", lo=0.0)
        with ck.at("clutter_rate"):
            changes["sensors"] = tuple(dataclasses.replace(x, clutter_rate=rate)
                                       for x in s.sensors)
    if "clutter" in ov:
        kind = ov["clutter"]
        if kind not in ("uniform", "gmm"):
            raise ValueError(f"clutter: unknown {kind!r} (expected uniform, gmm)")
        rate = s.clutter_rate(s.first)
        if kind == "uniform":
            clutter = UniformClutter(s.region, rate)
        elif isinstance(clutter, UniformClutter):
            clutter = default_mixture(s.region, rate)
    if "clutter_rate" in ov:
        clutter = _with_rate(clutter, ck.number(ov["clutter_rate"], "clutter_rate", lo=0.0))
    changes["clutter"] = clutter
    if "pd" in ov:
        changes["pd"] = ck.detection_probability(ov["pd"], "pd")
    if "scans" in ov:
        n = ck.integer(ov["scans"], "scans", lo=1)
        if n > MAX_SCANS:
            raise ValueError(f"scans: {n} scans, more than the maximum {MAX_SCANS} (MAX_SCANS)")
        changes["scans"] = (s.first, s.first + n - 1)
    if "truth_sigma_v" in ov:
        changes["truth_sigma_v"] = ck.number(
            ov["truth_sigma_v"], "truth_sigma_v", lo=0.0, hi=MAX_SIGMA_V, unit="m/s²"
        )
    if "sigma_range" in ov:
        sr = ck.number(
            ov["sigma_range"], "sigma_range", lo=0.0, lo_open=True, hi=MAX_SIGMA, unit="m"
        )
        polar = PolarRadar | RotatingRadar
        if not any(isinstance(x, polar) for x in s.sensors):
            raise ValueError(f"sigma_range: scenario {s.name!r} has no polar sensor")
        changes["sensors"] = tuple(
            dataclasses.replace(x, sigma_range=sr) if isinstance(x, polar) else x
            for x in changes.get("sensors", s.sensors)
        )
    return dataclasses.replace(s, **changes)
