"""Bounds of a scenario and the checks of its scalar fields.

A scenario beyond these bounds is refused up front, before any memory is allocated or a
number overflows (``docs/scenarios.md``, "Limits"). Sensor limits: ``MAX_SIGMA`` (m),
``MAX_SIGMA_BEARING_DEG`` in :mod:`mhtrack.models.sensors`; ``MAX_COORDINATE`` in
:mod:`mhtrack.records`. Every check raises ``ValueError`` starting with the key path.
"""

from __future__ import annotations

from typing import Any

from mhtrack.models.clutter import Region
from mhtrack.records import MAX_COORDINATE
from mhtrack.scenario import _check as ck

#: Largest number of scans of a scenario (``last − first + 1``).
MAX_SCANS = 100_000
#: Largest expected number of plots of one simulation: sensors × mean clutter rate × scans
#: plus the target plots (each plot costs about 100 bytes in the tables).
MAX_PLOTS = 50_000_000
#: Largest scan period ``T`` (s): about 11.6 days.
MAX_T = 1e6
#: Largest ``|velocity component|`` of a target (m/s): 100 km/s.
MAX_SPEED = 1e5
#: Largest truth acceleration noise ``truth_sigma_v`` (m/s²): about 1000 g.
MAX_SIGMA_V = 1e4#: Largest scan index: scan times ``k·T`` and int64 scan arrays stay exact.
MAX_SCAN_INDEX = 2**53


def check_period(v: object) -> float:
    """The scan period ``T`` (s): ``0 < T <= MAX_T``."""
    return ck.number(v, "T", lo=0.0, lo_open=True, hi=MAX_T, unit="s")


def check_sigma_v(v: object) -> float:
    """The truth acceleration noise (m/s²): ``0 <= σv <= MAX_SIGMA_V``."""
    return ck.number(v, "truth_sigma_v", lo=0.0, hi=MAX_SIGMA_V, unit="m/s²")


def check_scan_range(first: object, last: object) -> tuple[int, int]:
    """Validated ``(first, last)``; at most :data:`MAX_SCANS` scans."""
    f = ck.integer(first, "scans[0]", lo=0, hi=None)
    la = ck.integer(last, "scans[1]", lo=0, hi=None)
    if f > la:
        raise ValueError(f"scans: first must be <= last, got [{f}, {la}]")
    if la - f + 1 > MAX_SCANS:
        raise ValueError(
            f"scans: [{f}, {la}] is {la - f + 1} scans, more than the maximum {MAX_SCANS} "
            f"(MAX_SCANS)"
        )
    if la > MAX_SCAN_INDEX:
        raise ValueError(f"scans[1]: must be <= {MAX_SCAN_INDEX} (2**53), got {la}")
    return f, la


def check_region(r: Region, path: str) -> None:
    for k in ("xmin", "xmax", "ymin", "ymax"):
        ck.bounded(getattr(r, k), ck.join(path, k), MAX_COORDINATE)


def check_state(state: Any, path: str) -> None:
    """``[x, vx, y, vy]`` within ±:data:`MAX_COORDINATE` m and ±:data:`MAX_SPEED` m/s."""
    for j, v in enumerate(state):
        if j % 2 == 0:
            ck.bounded(v, f"{path}[{j}]", MAX_COORDINATE)
        else:
            ck.bounded(v, f"{path}[{j}]", MAX_SPEED, "m/s")
