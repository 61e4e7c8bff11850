"""Hard caps: limits that scale with the scene, counting what they cut at each scan, and
telling the user.

**Scaled limits** (:func:`scaled_limits`, issue 18). The work of a scan grows with its
plots ``n`` (every plot may start a tree, each tree's leaves gate the next plots) and
with the confirmed tracks ``t`` carried into it. With ``n' = min(n, BURST_PLOTS)``:

======================== ==============================================
``max_births_per_scan``  ``max(floor, n')``
``max_trees``            ``max(floor, 5·n' + t)``
``max_leaves``           ``max(floor, 16·n' + 50·t)``
``max_gated_pairs``      ``max(floor, 150·n' + 50·t)``
======================== ==============================================

the floors being the configured values (``MHTConfig``), so that nothing changes up to
~900 plots and 100 tracks per scan, and a burst of more than ``BURST_PLOTS`` plots gets
the limits of ``BURST_PLOTS``. ``max_trees``' floor is per rotating sensor: with frames of
several sensors (each one radar's sector, :attr:`~mhtrack.mht.coverage.Coverage.n_sensors`,
which counts the sensors with a rotation period) the
store holds the trees of every radar's last rotations while ``n`` counts one sector's
plots, so the floor is the configured value times the sensors (issue 30: 30 radars and
4 000 aircraft hold ~20 000 trees, which a floor of 5 000 cut at nearly every frame).

**Overload rule** (:func:`mhtrack.mht.pruning.cap_per_plot`, with ``scale_caps``). A
scan of ``n`` plots entered with ``t`` confirmed tracks supports ``16·n' + 50·t`` leaves
(:func:`scene_leaves`: ``max_leaves``' scaled value without its floor). At a scan where,
after SPRT deletion and score-drop pruning, the children exceed that (less this scan's
births) **and** a leaf cap would act — some tree has more than ``max_leaves_per_tree``
children, or all trees more than ``max_leaves`` less the births — the children are
first cut to what the scan can use: each plot keeps its ``CHILDREN_PER_PLOT`` best
children over all trees, each tree its ``MISSES_PER_TREE`` best miss children (ties:
lower index). The best global hypothesis uses a plot at most once and a tree at most
once, so these are its alternatives for every plot and every tree; at most
``4·n + 2·trees`` children are kept, proportional to the scan's plots and trees
instead of ``300·trees``, and a clutter burst stays bounded by them. The fixed caps
still apply after it. Counted as ``max_leaves_per_plot`` (children cut) in
``StepStats.caps``.

Where a leaf cap would act but the children stay within ``16·n' + 50·t`` (less the
births) — a scene of many targets in dense clutter, e.g. 1 000 targets in 5 000 clutter
plots per scan — the same cut applies to the **tentative** trees' children only (ranked
among themselves; the confirmed trees' children are all kept for the fixed caps), counted
as ``max_tentative_per_plot``. Both act only at scans where a leaf cap would act, so a
run in which no leaf cap acts is unchanged.

It acts only where the old caps acted. Within the budget (1 000 targets in 5 000
clutter plots) it spares the confirmed trees, which hold the targets; the tentative
trees, mostly clutter, get 4 children per plot and 2 misses per tree (``docs/mht.md``).
MHT-GMM and MHT-AGMM on ``crossing``, ``opensky``, ``multiradar`` never meet it; plain
MHT (known κ = 1e−9: every clutter plot is worth a new tree, every tree branches on every
plot) meets it on nearly every scan and keeps ~300 leaves instead of ~10 000
(``docs/mht.md``, *Hard caps*).

Nothing here depends on time: the same input gives the same cuts on any machine.
"""

from __future__ import annotations

import copy
import dataclasses
import logging

from mhtrack.bounds import int_problem
from mhtrack.mht.config import MHTConfig

#: The tracker's logger (the name users and the Monte-Carlo runner filter on).
logger = logging.getLogger("mhtrack.mht.tracker")

#: Plots per scan beyond which the limits stop growing (a clutter burst).
BURST_PLOTS = 20_000
#: Coefficients of :func:`scaled_limits` (per plot ``n'``, per confirmed track ``t``).
TREES_PER_PLOT, LEAVES_PER_PLOT, PAIRS_PER_PLOT = 5, 16, 150
LEAVES_PER_TRACK = PAIRS_PER_TRACK = 50
#: The overload rule (module docstring): children kept per plot, misses kept per tree.
CHILDREN_PER_PLOT, MISSES_PER_TREE = 4, 2
#: The caps :func:`scaled_limits` scales.
SCALED = ("max_births_per_scan", "max_trees", "max_leaves", "max_gated_pairs")


def scaled_limits(cfg: MHTConfig, n_plots: int, n_tracks: int,
                  n_sensors: int = 1) -> dict[str, int]:
    """The limits of a scan of ``n_plots`` plots entered with ``n_tracks`` confirmed
    tracks, the store holding the trees of ``n_sensors`` sensors' frames (module
    docstring); the configured values when ``cfg.scale_caps`` is off."""
    floors = {k: int(getattr(cfg, k)) for k in SCALED}
    if not cfg.scale_caps:
        return floors
    floors["max_trees"] *= max(int(n_sensors), 1)
    n, t = min(int(n_plots), BURST_PLOTS), int(n_tracks)
    return {
        "max_births_per_scan": max(floors["max_births_per_scan"], n),
        "max_trees": max(floors["max_trees"], TREES_PER_PLOT * n + t),
        "max_leaves": max(floors["max_leaves"], _leaves_supported(n, t)),
        "max_gated_pairs": max(floors["max_gated_pairs"],
                               PAIRS_PER_PLOT * n + PAIRS_PER_TRACK * t),
    }


def scene_leaves(cfg: MHTConfig, n_plots: int, n_tracks: int) -> int | None:
    """The leaves a scan of ``n_plots`` plots entered with ``n_tracks`` confirmed tracks
    supports, ``16·n' + 50·t`` — :func:`scaled_limits`' ``max_leaves`` without its
    floor — above which the overload rule may act (module docstring); ``None`` when
    ``cfg.scale_caps`` is off."""
    if not cfg.scale_caps:
        return None
    return _leaves_supported(min(int(n_plots), BURST_PLOTS), int(n_tracks))


def _leaves_supported(n: int, t: int) -> int:
    """``16·n' + 50·t`` leaves for ``n' = n`` plots (already bounded by
    :data:`BURST_PLOTS`) and ``t`` confirmed tracks."""
    return LEAVES_PER_PLOT * n + LEAVES_PER_TRACK * t


def scan_config(cfg: MHTConfig, n_plots: int, n_tracks: int,
                n_sensors: int = 1) -> MHTConfig:
    """``cfg`` with :func:`scaled_limits` for this scan (``cfg`` itself when they are its
    own values). Once per frame: the copy skips :class:`MHTConfig`'s checks of the
    fields it keeps (checked when ``cfg`` was made) when the scaled ones pass theirs
    (integers within :data:`~mhtrack.bounds.MAX_INDEX`, ≥ the configured ones, hence
    ≥ 1; ``max_leaves > max_births_per_scan``); else ``dataclasses.replace`` raises as
    before."""
    lim = scaled_limits(cfg, n_plots, n_tracks, n_sensors)
    if all(lim[k] == getattr(cfg, k) for k in SCALED):
        return cfg
    if (any(int_problem(v) is not None or v < getattr(cfg, k) for k, v in lim.items())
            or lim["max_leaves"] <= lim["max_births_per_scan"]):
        return dataclasses.replace(cfg, **lim)
    out = copy.copy(cfg)
    for k, v in lim.items():
        object.__setattr__(out, k, v)
    return out


def describe(caps: dict[str, int], limits: dict[str, int] | None = None) -> str:
    """``"max_births_per_scan 50256 (limit 20000), ..."``: the caps that acted, each with
    its count (what it cut, or for ``fusion_greedy`` the plots it assigned greedily) and,
    when known, the limit it had at that scan."""
    parts = []
    for k in sorted(caps):
        lim = None if limits is None else limits.get(k)
        parts.append(f"{k} {caps[k]}" + ("" if lim is None else f" (limit {lim})"))
    return ", ".join(parts)


class CapWarnings:
    """A warning the first time each cap acts; every scan's counts at DEBUG. One line:
    ``MHT scan 2 (70256 plots): hard caps acted: max_births_per_scan 50256 (limit 20000)
    (first time for max_births_per_scan; ...)``."""

    def __init__(self) -> None:
        self.warned: set[str] = set()

    def __call__(self, scan_index: int, caps: dict[str, int], n_plots: int | None = None,
                 limits: dict[str, int] | None = None) -> None:
        if not caps:
            return
        where = f"MHT scan {scan_index}" + ("" if n_plots is None else f" ({n_plots} plots)")
        new = sorted(set(caps) - self.warned)
        if new:
            self.warned.update(new)
            logger.warning(
                "%s: hard caps acted: %s (first time for %s; per-scan counts are in "
                "StepStats.caps)", where, describe(caps, limits), ", ".join(new))
        else:
            logger.debug("%s: hard caps acted: %s", where, describe(caps, limits))
