"""Per-radar clutter estimate error on ``opensky-radars``: local plane vs range/bearing.

Usage (docs/clutter.md, "Per radar, in its own range and bearing")::

    mhtrack simulate opensky-radars --seed 1 --out out/or1
    python docs/examples/clutter_frames.py out/or1 mht-agmm polar

Tracks the whole run and every 120 s sums ``|κ̂ − κ|`` over each radar's disc on a
150 × 180 range–bearing grid (area element ``r dr dθ``), relative to the true mass per
rotation; prints the mean over the run per radar as one JSON line. The true κ per m² per
rotation is the simulator's own model (``ClutterPatch``, ``sample_range_azimuth``):
``rate / (2π R_max) / r`` plus ``rate_p N(r; μ_r, σ_r) N(θ; μ_θ, σ_θ) / r``.
"""

from __future__ import annotations

import json
import sys

import numpy as np

from mhtrack.build import make_tracker
from mhtrack.io import read_plots
from mhtrack.io.sensors import read_sensors
from mhtrack.models.geodesy import polar_to_local
from mhtrack.scenario.presets import OPENSKY_RADAR_MAX_RANGE, OPENSKY_ROTATING_RADARS


def main(directory: str, tracker: str, frame: str) -> None:
    sensors = read_sensors(f"{directory}/sensors.toml")
    table = read_plots(f"{directory}/plots.csv", sensors=sensors)
    trk = make_tracker(tracker, sensors=sensors, clutter_frame=frame)
    big_r, nr, nt = OPENSKY_RADAR_MAX_RANGE, 150, 180
    rr, tt = np.meshgrid((np.arange(nr) + 0.5) * big_r / nr,
                         (np.arange(nt) + 0.5) * 360.0 / nt, indexing="ij")
    area = rr * (big_r / nr) * np.radians(360.0 / nt)
    grid, truth = {}, {}
    for i, (_, site, *_rest, rate, patch) in enumerate(OPENSKY_ROTATING_RADARS, 1):
        grid[i], _ = polar_to_local(sensors.frame(), site[0], site[1], rr.ravel(),
                                    tt.ravel(), 1.0, 0.1)
        pr, pb, psr, psb, prate = patch
        db = (tt - pb + 180.0) % 360.0 - 180.0
        g = (np.exp(-0.5 * ((rr - pr) / psr) ** 2) / (np.sqrt(2 * np.pi) * psr)
             * np.exp(-0.5 * (db / psb) ** 2) / (np.sqrt(2 * np.pi) * np.radians(psb)))
        truth[i] = (rate / (2 * np.pi * big_r) + prate * g) / rr
    errors: dict[int, list[float]] = {i: [] for i in grid}
    next_t = 120.0
    for scan in table.scans():
        trk.step(scan)
        if scan.time < next_t:
            continue
        next_t += 120.0
        for i in grid:
            if trk.clutter.has_estimate(i):
                k = trk.clutter.estimator(i).intensity(grid[i]).reshape(rr.shape)
                errors[i].append(float(np.sum(np.abs(k - truth[i]) * area)
                                       / np.sum(truth[i] * area)))
    print(json.dumps({"tracker": tracker, "frame": frame,
                      "relative_l1": {i: round(float(np.mean(v)), 3)
                                      for i, v in errors.items()}}))


if __name__ == "__main__":
    main(*sys.argv[1:4])
