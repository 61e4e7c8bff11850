"""The tracker's defaults fitted to what is known of the data (:func:`default_config`):
P1 §3's parameters, with the new-target density scaled to the surveillance area
(:func:`birth_density_for_area`: a scenario's region or a plots file's robust bounding
box, :func:`plots_area`) and, with one sensor, that sensor's ``P_D`` (at most
:data:`MAX_TRACKER_PD`) and Cartesian ``σ``; and the fusion of several sensors
(:func:`default_fusion`)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from mhtrack.mht import MHTConfig
from mhtrack.models.sensors import CartesianSensor

if TYPE_CHECKING:
    from mhtrack.scenario import Scenario

#: Default known clutter density of the plain MHT (P1 §3: 1e−9 per m²).
DEFAULT_CLUTTER_DENSITY = 1e-9


#: New targets per scan that P1's λv = 1e−7 per m² means over P1's 8 km × 8 km region
#: (P1 §3): 6.4. :func:`default_config` keeps this rate and scales the density to the
#: surveillance area at hand, so that P1's value is used on P1's region and a 500 km
#: air-surveillance picture does not expect 29 000 new targets per scan.
P1_BIRTHS_PER_SCAN = 1e-7 * 8000.0**2

#: Largest ``P_D`` the tracker takes from a scenario: a sensor with ``P_D = 1`` would make
#: one missed plot (gating, a plot lost in fusion) cost ``ln 0``; at 0.999 a miss costs
#: ``ln 0.001 ≈ −6.9``, two delete the track (``β = 1e−4``).
MAX_TRACKER_PD = 0.999


def capped_pd(pd: float) -> float:
    """``min(P_D, MAX_TRACKER_PD)``: the detection probability the tracker assumes for
    sensors detecting with ``pd``."""
    return min(pd, MAX_TRACKER_PD)


def birth_density_for_area(area: float) -> float:
    """``λv = 6.4 / A`` per m² per scan: P1's new-target rate over an area of ``A`` m²."""
    if not (np.isfinite(area) and area > 0):
        raise ValueError(f"surveillance area must be finite and > 0, got {area}")
    return P1_BIRTHS_PER_SCAN / area


def default_config(scenario: Scenario | None = None, *, area: float | None = None) -> MHTConfig:
    """The tracker defaults (:class:`MHTConfig`, P1 §3) fitted to what is known of the data.

    * The new-target density is scaled to the surveillance area — the scenario's region,
      or ``area`` (e.g. :func:`plots_area` of a plots file) — by
      :func:`birth_density_for_area`; P1's crossing region gives P1's 1e−7.
    * With a scenario of **one** sensor, the tracker's ``P_D`` is that sensor's
      (:func:`capped_pd`), and with a Cartesian sensor ``σw`` is its ``sigma`` (its plots
      carry no covariance of their own; polar plots do). With several sensors the scans
      are fused first and a fused plot's detection probability is not one sensor's, so
      ``P_D`` stays P1's 0.9. On P1's crossing (``P_D`` 0.9, σ 100 m) nothing changes.
    """
    if scenario is None:
        return MHTConfig() if area is None else MHTConfig(
            new_target_density=birth_density_for_area(area))
    changes: dict[str, Any] = {"new_target_density": birth_density_for_area(
        scenario.region.area)}
    if len(scenario.sensors) == 1:
        changes["p_detection"] = capped_pd(float(scenario.pd[0]))
        sensor = scenario.sensors[0]
        if isinstance(sensor, CartesianSensor):
            changes["sigma_w"] = float(sensor.sigma)
    return MHTConfig(**changes)


def config_with(config: MHTConfig | None = None, **changes: Any) -> MHTConfig:
    """``config`` (default :class:`MHTConfig`) with the non-``None`` ``changes`` applied."""
    config = MHTConfig() if config is None else config
    return dataclasses.replace(config, **{k: v for k, v in changes.items() if v is not None})


#: The surveillance area of plots without a scenario is the box between these quantiles
#: of their x and y (so a few wild plots do not inflate it).
AREA_QUANTILES = (0.005, 0.995)


@dataclass(frozen=True)
class PlotsArea:
    """The robust bounding box of a set of plots (see :func:`plots_area`)."""

    x0: float
    x1: float
    y0: float
    y1: float
    #: Box sides (m), each at least 1 m.
    width: float
    height: float
    #: Plots farther outside the box than its own width (east-west) or height.
    n_far: int

    @property
    def area(self) -> float:
        """``width × height`` (m²)."""
        return self.width * self.height


def plots_area(x: npt.ArrayLike, y: npt.ArrayLike) -> PlotsArea:
    """The box between the :data:`AREA_QUANTILES` (0.5 % and 99.5 %) of the plots' ``x``
    and ``y`` (each side at least 1 m), and how many plots lie farther outside it than
    its width or height — a surveillance area for :func:`default_config` when no scenario
    gives the region."""
    x, y = np.asarray(x), np.asarray(y)
    (x0, x1), (y0, y1) = (np.quantile(v, AREA_QUANTILES) for v in (x, y))
    wx, wy = max(float(x1 - x0), 1.0), max(float(y1 - y0), 1.0)
    with np.errstate(over="ignore", invalid="ignore"):
        far = (x < x0 - wx) | (x > x1 + wx) | (y < y0 - wy) | (y > y1 + wy)
    return PlotsArea(x0, x1, y0, y1, wx, wy, int(np.count_nonzero(far)))


def known_kappa_mismatch(scenario: Scenario,
                         kappa: float = DEFAULT_CLUTTER_DENSITY) -> float | None:
    """The scenario's mean clutter density ``S λ̄ / A`` when it is over 10× ``kappa`` or
    (being > 0) under a tenth of it — a tracker assuming ``kappa`` then scores its plots
    mostly as targets, or its targets as clutter; ``None`` when they are close."""
    mean = scenario.mean_clutter_density()
    if mean > 10 * kappa or 0 < mean < 0.1 * kappa:
        return mean
    return None



def default_fusion(n_sensors: int) -> str:
    """The tracker's fusion: ``"adaptive-kmeans"`` with more than one sensor (the MHT
    assumes at most one plot per target per scan), else ``"none"``."""
    return "adaptive-kmeans" if n_sensors > 1 else "none"

