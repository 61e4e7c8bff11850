"""Why aircraft are not held on the dense scene of issue 30 (``bench_dense.py``'s scene and
``held``): per scan the aircraft covered (paired within the gate with a confirmed track
reported at that scan) and the confirmed rows paired to none; the aircraft not held, split
into first covered after the first held scan ("late") and covered by then with a gap later;
and at each gap where the aircraft was detected, whether its track (the id it had before)
was reported farther than the gate or not reported at all.

``--attributes``: the plots with secondary-radar attributes (``bench_dense.py
--attributes``).

Run: ``PYTHONPATH=src python benchmarks/dense_held_why.py [--config JSON] [--seed 1]
[--attributes]``.
"""

from __future__ import annotations

import argparse
import collections
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def main(argv: list[str] | None = None) -> int:
    from scipy.optimize import linear_sum_assignment
    from scipy.spatial.distance import cdist

    from bench_dense import dense_scene
    from mhtrack.build import make_tracker
    from mhtrack.experiments import track

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", default="{}", help="MHTConfig fields to change (JSON)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--scans", type=int, default=20)
    ap.add_argument("--held-scans", type=int, default=10)
    ap.add_argument("--gate", type=float, default=300.0)
    ap.add_argument("--attributes", action="store_true",
                    help="plots with secondary-radar attributes (module docstring)")
    a = ap.parse_args(argv)
    sim, cfg, name, kappa = dense_scene(a.scans, a.seed, a.attributes,
                                        json.loads(a.config))
    trk = make_tracker(name, cfg, clutter_density=kappa)
    c0 = time.process_time()
    run = track(trk, sim.plots, name=name, output="online")
    cpu = (time.process_time() - c0) / a.scans
    ids = np.unique(sim.truth.target_id)
    scans = sorted(int(s) for s in np.unique(sim.truth.scan))
    by = np.full((len(scans), ids.size), -1)
    det = np.zeros((len(scans), ids.size), bool)
    unpaired = []
    P, T, R = sim.plots, sim.truth, run.tracks
    for k, s in enumerate(scans):
        o = P.origin[P.scan == s]
        det[k, np.searchsorted(ids, o[o >= 0])] = True
        tr, tt = np.flatnonzero(R.scan == s), np.flatnonzero(T.scan == s)
        if tr.size == 0:
            unpaired.append(0)
            continue
        d = cdist(R.positions[tr], T.positions[tt])
        cost = np.where(d <= a.gate, d, 1e9)
        r, c = linear_sum_assignment(cost)
        keep = cost[r, c] <= a.gate
        by[k, np.searchsorted(ids, T.target_id[tt[c[keep]]])] = R.track_id[tr[r[keep]]]
        unpaired.append(int(tr.size - keep.sum()))
    h0 = len(scans) - a.held_scans
    held = (by[h0:] >= 0).all(axis=0)
    bad = np.flatnonzero(~held)
    first = np.array([int(np.argmax(by[:, j] >= 0)) if (by[:, j] >= 0).any() else 10**6
                      for j in bad])
    late = int((first > h0).sum())
    gaps: collections.Counter[str] = collections.Counter()
    for j in bad:
        for k in range(len(scans)):
            before = by[:k, j][by[:k, j] >= 0]
            if by[k, j] >= 0 or not det[k, j] or before.size == 0:
                continue
            m = (R.scan == scans[k]) & (R.track_id == before[-1])
            t = (T.scan == scans[k]) & (T.target_id == ids[j])
            if not m.any():
                gaps["track not reported"] += 1
            elif np.linalg.norm(R.positions[m][0] - T.positions[t][0]) > a.gate:
                gaps[f"reported > {a.gate:g} m away"] += 1
            else:
                gaps["reported within the gate, paired elsewhere"] += 1
    covered = (by >= 0).sum(axis=1).tolist()
    print(json.dumps({
        "config": json.loads(a.config), "seed": a.seed, "attributes": a.attributes,
        "held": float(held.mean()),
        "cpu_per_scan": cpu, "covered_per_scan": covered,
        "unpaired_confirmed_rows_mean_held_scans": float(np.mean(unpaired[h0:])),
        "track_ids": int(np.unique(R.track_id).size), "not_held": int(bad.size),
        "late": late, "gap_later": int(bad.size) - late, "at_detected_gaps": dict(gaps)}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
