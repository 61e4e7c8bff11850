"""``--clutter-half-life``, ``--clutter-forgetting``, ``--birth-scaling``,
``--map-range-cell``, ``--map-sectors``: the parameters of the trackers ``mht-map``,
``mht-fgmm`` and ``mht-mapgmm`` (``docs/clutter.md``), for
``mhtrack run``, ``mhtrack track`` and ``mhtrack live``, turned into the ``clutter_params`` of
:func:`mhtrack.build.make_tracker` (each bounded here and by the estimator)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import click

from mhtrack.cli.common import BoundedInt

#: Option → (keyword, the estimators that take it).
TAKES: dict[str, tuple[str, tuple[str, ...]]] = {
    "--clutter-forgetting": ("forgetting", ("map", "fgmm", "mapgmm")),
    "--birth-scaling": ("birth_scaling", ("map", "mapgmm")),
    "--map-range-cell": ("range_cell", ("map", "mapgmm")),
    "--map-sectors": ("n_azimuth", ("map", "mapgmm")),
    "--clutter-half-life": ("half_life", ("map", "fgmm", "mapgmm")),
}


def clutter_estimator_options(f: Callable[..., Any]) -> Callable[..., Any]:
    """The five options (module docstring); each defaults to the estimator's own."""
    opts = [
        click.option("--clutter-forgetting", type=click.FloatRange(0, 1, min_open=True),
                     default=None, help="A constant forgetting factor γ per rotation or "
                     "scan of the clutter estimate (mht-map, mht-fgmm, mht-mapgmm) instead "
                     "of the half-life (not both); 1: no forgetting [map, mapgmm: none, the "
                     "half-life's; fgmm: 0.7]."),
        click.option("--birth-scaling", type=click.FloatRange(0, 10), default=None,
                     help="mht-map, mht-mapgmm: β of the birth density the clutter map "
                     "drives, s(z) = min(1, ρ̄/κ̂(z))^β; 0: none [0]."),
        click.option("--map-range-cell", type=click.FloatRange(1, 1e6), default=None,
                     help="mht-map, mht-mapgmm: range cell (m) of the clutter map [the "
                     "radar's reach / 24 (map) or / 12 (mapgmm); 500 without one]."),
        click.option("--map-sectors", type=BoundedInt(1, 65536), default=None,
                     help="mht-map, mht-mapgmm: bearing sectors of the clutter map [64 "
                     "(map) or 32 (mapgmm) with a reach, else 64]."),
        click.option("--clutter-half-life", type=click.FloatRange(0, None, min_open=True),
                     default=None, help="Half-life (s of data time) of the clutter "
                     "estimate's memory (mht-map, mht-fgmm, mht-mapgmm) instead of the forgetting "
                     "factor (not both) [map, mapgmm: 40 s; fgmm: none, γ = 0.7 per scan]."),
    ]
    for opt in reversed(opts):
        f = opt(f)
    return f


def clutter_params(tracker: str, clutter_forgetting: float | None,
                   birth_scaling: float | None, map_range_cell: float | None,
                   map_sectors: int | None, clutter_half_life: float | None = None
                   ) -> dict[str, Any] | None:
    """The ``clutter_params`` of the options given (``None`` when none is); a usage error
    naming the option when ``tracker``'s estimator does not take it, or when both the
    forgetting factor and the half-life are given."""
    from mhtrack.build import TRACKER_ESTIMATORS

    estimator = TRACKER_ESTIMATORS.get(tracker)
    given = dict(zip(TAKES, (clutter_forgetting, birth_scaling, map_range_cell,
                             map_sectors, clutter_half_life), strict=True))
    if clutter_forgetting is not None and clutter_half_life is not None:
        raise click.UsageError("--clutter-forgetting or --clutter-half-life, not both (a "
                               "constant factor per scan, or a memory in data time)")
    out: dict[str, Any] = {}
    for flag, value in given.items():
        if value is None:
            continue
        key, takers = TAKES[flag]
        if estimator not in takers:
            trackers = " or ".join(f"mht-{e}" for e in takers)
            raise click.UsageError(f"{flag} goes with --tracker {trackers} "
                                   f"(not {tracker})")
        out[key] = value
    return out or None
