"""The defaults of timed plots from rotating radars, taken from the radars themselves
(:func:`radar_rule`) rather than from P1's 8 km × 8 km box (``docs/real-radar.md``).

A frame of a rotating radar is one look at each position its beam sweeps, and the
tracker scores misses, the clutter ``κ`` and the new-target density ``λv`` per m² per
*look* (:mod:`mhtrack.mht.coverage`, :mod:`mhtrack.clutter.per_sensor`). For each radar
``r`` with a site, a rotation period ``T_r`` and plots in the input:

* **reach** ``R_r``: its ``max_range`` from the sensors file, else learned from its
  plots by the rule the tracker learns it with online (:mod:`mhtrack.mht.reach`: per
  azimuth sector the 2nd largest of the per-rotation farthest plots), here over the
  whole input; the area it covers ``A_r = π R_r²`` (learned: ``Σ_s π R_s² / S``) and its
  reach is quoted as ``√(A_r/π)``;
* **plot density per look** ``ρ_r = n_r / (K_r A_r)``: its ``n_r`` plots over the
  ``K_r`` rotations that hold them (rotation ``⌊(t − t_first) / T_r⌋``; a gap in the
  recording does not count), spread over its area;
* **new targets per look** ``λ_r = ρ_r · T_r / D_r``: a target is new on one of the
  ``D_r / T_r`` looks it takes to cross the radar's reach, ``D_r = (π/2) R_r / v_max``
  (the mean chord of a disc of radius ``R`` is ``πR/2``; ``v_max`` the tracker's
  largest speed makes ``D_r`` the shortest dwell, so ``λ_r`` the largest). Counting every
  plot as a possible target (clutter included) errs on the same side.

The tracker takes one value of each: ``λv = median_r λ_r`` and, as the known clutter
density of ``--tracker mht``, ``κ = median_r ρ_r`` — at most every plot is clutter (the
other trackers estimate ``κ̂`` per radar, a rotation at a time; before a radar's first
rotation they keep :data:`~mhtrack.build.DEFAULT_CLUTTER_DENSITY`: with the plots'
``ρ`` instead, seed 1 of ``opensky-radars`` gave the same evaluation to the last digit,
and ``mhtrack live``, which has no plots to survey, gives the same tracks as a run on
the recording). Deletion is already per look:
Wald's lower threshold ``ln(β/(1−α))`` is reached after
``k_r = ⌈ln(β/(1−α)) / ln(1 − P_D,r)⌉`` missed looks of radar ``r`` in a row, ``k_r T_r``
seconds (:func:`misses_to_delete`); the note states it for each radar.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from mhtrack.mht.reach import RANK, SECTORS
from mhtrack.models.radars import SensorSet


@dataclass(frozen=True)
class RadarFigures:
    """What one rotating radar's plots say (module docstring)."""

    sensor: int
    #: Rotation period ``T`` (s).
    period: float
    #: Area within reach (m²) and whether the reach was learned from the plots.
    area: float
    learned: bool
    #: Plots per rotation ``n / K``.
    plots_per_rotation: float
    #: ``P_D`` of the sensors file.
    pd: float

    @property
    def reach(self) -> float:
        """``√(A/π)`` (m): ``max_range``, or the learned reach's equivalent radius."""
        return math.sqrt(self.area / math.pi)

    @property
    def density(self) -> float:
        """``ρ = (n / K) / A``: plots per m² per look."""
        return self.plots_per_rotation / self.area

    def crossing_s(self, v_max: float) -> float:
        """``D = (π/2) R / v_max`` (s): the mean time to cross the reach at ``v_max``."""
        return 0.5 * math.pi * self.reach / v_max

    def new_target_density(self, v_max: float) -> float:
        """``λ = ρ T / D`` per m² per look."""
        return self.density * self.period / self.crossing_s(v_max)


def misses_to_delete(pd: float, alpha: float, beta: float) -> int:
    """``⌈ln(β/(1−α)) / ln(1 − P_D)⌉``: missed looks in a row that delete a track whose
    score is at its peak (Wald's lower SPRT threshold, :mod:`mhtrack.mht.sprt`)."""
    return math.ceil(math.log(beta / (1.0 - alpha)) / math.log1p(-min(pd, 0.999)))


@dataclass(frozen=True)
class RadarRule:
    """The defaults of :func:`radar_rule`: per-radar figures and the tracker's values."""

    radars: tuple[RadarFigures, ...]
    v_max: float

    @property
    def new_target_density(self) -> float:
        """``λv = median_r ρ_r T_r / D_r`` (per m² per look)."""
        return float(np.median([r.new_target_density(self.v_max) for r in self.radars]))

    @property
    def clutter_density(self) -> float:
        """``κ = median_r ρ_r`` (per m² per look)."""
        return float(np.median([r.density for r in self.radars]))

    def note(self, alpha: float, beta: float, *, birth: bool = True,
             known: bool = False) -> str:
        """The line naming the rule and each radar's figures (``birth``: with ``λv``;
        ``known``: with the known clutter density of ``--tracker mht``)."""
        parts = []
        for r in self.radars:
            how = "learned" if r.learned else "max_range"
            k = misses_to_delete(r.pd, alpha, beta)
            parts.append(
                f"radar {r.sensor} ({r.period:g} s, reach {r.reach / 1e3:.0f} km {how}, "
                f"{r.plots_per_rotation:.3g} plots a rotation: ρ {r.density:.3g}, "
                f"λ {r.new_target_density(self.v_max):.3g}; deleted after {k} missed "
                f"looks, {k * r.period:g} s)")
        head = (f"new-target density λv = {self.new_target_density:.4g} per m² per look: "
                "the median over the radars of λ = ρ·T/D, ρ each radar's plots per rotation "
                "over the area within its reach, T its period, D = (π/2)·reach / "
                f"{self.v_max:g} m/s the time to cross it (--birth-density sets it); "
                if birth else "")
        kappa = (f"clutter κ = {self.clutter_density:.4g} per m² per look (the median ρ; "
                 "--clutter-density sets it); " if known else "")
        return f"{head}{kappa}" + "; ".join(parts)


def radar_rule(sensors: SensorSet | None, sensor: npt.ArrayLike | None,
               time: npt.ArrayLike | None, x: npt.ArrayLike | None, y: npt.ArrayLike | None,
               *, v_max: float) -> RadarRule | None:
    """The :class:`RadarRule` of the plots (``sensor, time, x, y`` in the local frame)
    of ``sensors``' rotating radars — those with a site, a period and at least two
    plots; ``None`` when there is none (then the defaults stay P1's)."""
    if sensors is None or sensor is None or time is None or x is None or y is None:
        return None
    sensor, time = np.asarray(sensor, np.int64), np.asarray(time, float)
    x, y = np.asarray(x, float), np.asarray(y, float)
    radars = []
    for s in sensors.sensors:
        mine = sensor == s.id
        n = int(np.count_nonzero(mine))
        if s.period is None or not s.has_site or n < 2:
            continue
        rot = np.floor((time[mine] - time[mine].min()) / s.period).astype(np.int64)
        rotations = np.unique(rot).size  # rotations holding plots: gaps do not count
        if s.max_range is not None:
            area, learned = math.pi * s.max_range**2, False
        else:
            area, learned = _learned_area(sensors, s.id, s.period, rot, x[mine], y[mine]), True
        if not area > 0:
            continue
        radars.append(RadarFigures(s.id, float(s.period), area, learned, n / rotations,
                                   float(s.pd)))
    return RadarRule(tuple(radars), float(v_max)) if radars else None


def _learned_area(sensors: SensorSet, sid: int, period: float, rot: np.ndarray,
                  x: np.ndarray, y: np.ndarray) -> float:
    """``Σ_s π R_s² / S`` of the reach :class:`~mhtrack.mht.reach.ReachEstimator` learns,
    over every rotation that holds plots (``rot``: each plot's rotation number): per
    sector the :data:`~mhtrack.mht.reach.RANK`-th largest of the per-rotation farthest
    plots (a rotation without plots in a sector counts 0), the largest while fewer
    rotations are held."""
    sx, sy = sensors.site_xy(sid)
    dx, dy = x - sx, y - sy
    sector = (np.floor(np.mod(np.degrees(np.arctan2(dx, dy)), 360.0) / 360.0 * SECTORS)
              .astype(np.int64) % SECTORS)
    _, k = np.unique(rot, return_inverse=True)
    maxima = np.zeros((int(k.max()) + 1, SECTORS))
    np.maximum.at(maxima, (k, sector), np.hypot(dx, dy))
    env = np.sort(maxima, axis=0)[-min(RANK, maxima.shape[0])]
    return float(math.pi * np.mean(env**2))
