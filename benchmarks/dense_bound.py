"""What perfect association would give on the dense scene of issue 30 (``bench_dense.py``'s
scene): an upper bound on ``held`` for the tracker's own scores and confirmation rules.

The tracker runs on the **aircraft's plots alone** (the clutter plots removed, the true κ
kept in every score, so each tree's branches are scored exactly as in the full scene),
with the frames' new-target densities ``λ_k`` those the full scene gives
(``MHTConfig.startup_density``: :class:`~mhtrack.mht.undetected.UndetectedDensity` on
every plot with the true κ; P1's constant ``λ_v`` without it). After each scan, each
aircraft's best score is the highest leaf score over the trees grown from its plots:
the branch through its own plots and misses, which no clutter branch can take from it
here. An aircraft is

* **confirmable** by scan ``s`` when that score reached ``threshold`` at some scan ≤ s
  (the SPRT's ``ln((1−β)/α)`` = 3.9 by default; lower thresholds are what a larger α or a
  logic rule with ``L > 0`` would ask);
* **kept** when, confirmable by the first held scan, its score stays > 0 at every held
  scan (a confirmed tree whose best leaf is ≤ 0 is left out of the global hypothesis and
  not reported).

``--attributes``: the plots with secondary-radar attributes as ``bench_dense.py
--attributes`` draws them (:func:`mhtrack.scenario.identity.with_attributes`), so that each
branch's score also holds the attributes' likelihood ratios.

Run: ``PYTHONPATH=src python benchmarks/dense_bound.py [--scans 20] [--held-scans 10]
[--seed 1] [--config JSON] [--attributes]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

THRESHOLDS = (None, 3.0, 2.0, 1.0, 0.0)


def only(plots: object, rows: np.ndarray) -> object:
    """The :class:`~mhtrack.records.PlotTable` of ``rows`` (mask) of ``plots``."""
    n = rows.size
    attrs = None if plots.attrs is None else plots.attrs.take(np.flatnonzero(rows))
    return dataclasses.replace(plots, attrs=attrs, **{
        f.name: getattr(plots, f.name)[rows] for f in dataclasses.fields(plots)
        if isinstance(getattr(plots, f.name), np.ndarray)
        and getattr(plots, f.name).shape[:1] == (n,)})


def main(argv: list[str] | None = None) -> int:
    from bench_dense import dense_scene
    from mhtrack.build import make_tracker
    from mhtrack.mht.undetected import UndetectedDensity

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", default='{"startup_density": true}',
                    help="MHTConfig fields to change (JSON)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--scans", type=int, default=20)
    ap.add_argument("--held-scans", type=int, default=10)
    ap.add_argument("--attributes", action="store_true",
                    help="plots with secondary-radar attributes (module docstring)")
    a = ap.parse_args(argv)
    sim, cfg, name, kappa = dense_scene(a.scans, a.seed, a.attributes,
                                        json.loads(a.config))
    trk = make_tracker(name, cfg, clutter_density=kappa)
    if cfg.startup_density:  # the full scene's densities, scan by scan
        u = UndetectedDensity(cfg.new_target_density)
        lam = iter([u.first_detection(s.z, np.full(len(s.z), kappa), cfg.p_detection)
                    for s in sim.plots.scans()])

        def density(frame: object, k: object, birth: object = trk.birth) -> float:
            birth._density = next(lam)
            return birth._density

        trk.birth.scan_density = density
    plots = only(sim.plots, sim.plots.origin >= 0)
    ids = np.unique(sim.truth.target_id)
    best = []
    for s in plots.scans():
        trk.step(s)
        lv = trk.leaves
        w = lv.window
        has = (w >= 0).any(axis=1)
        first = w[np.arange(len(w)), (w >= 0).argmax(axis=1)]
        air = np.searchsorted(ids, plots.origin[np.where(has, first, 0)])
        b = np.full(ids.size, -np.inf)
        np.maximum.at(b, air[has], lv.score[has])
        best.append(b)
    score = np.array(best)
    h0 = a.scans - a.held_scans  # index of the first held scan
    confirm = math.log((1 - cfg.beta) / cfg.alpha)
    rows = []
    for t in THRESHOLDS:
        thr = confirm if t is None else t
        reached = np.maximum.accumulate(score >= thr, axis=0)
        ok = reached[h0]
        kept = ok & (score[h0:] > 0).all(axis=0)
        rows.append({"threshold": round(thr, 3), "sprt": t is None,
                     "confirmable_by_first_held_scan": float(ok.mean()),
                     "kept_over_held_scans": float(kept.mean()),
                     "confirmable_by_last_scan": float(reached[-1].mean())})
    print(json.dumps({"config": json.loads(a.config), "seed": a.seed, "scans": a.scans,
                      "attributes": a.attributes,
                      "held_scans": a.held_scans, "aircraft": int(ids.size),
                      "bounds": rows}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
