"""Speed of the WGS-84 conversions of :mod:`mhtrack.models.geodesy`.

Run: ``python benchmarks/bench_geodesy.py``. Converts 100 000 polar plots of a site 150 km
from the origin (ranges up to 250 km, any bearing) into the local frame with their
covariances, and prints µs per plot beside references measured in the same run:
GeographicLib's pure-Python ``Geodesic.WGS84.Direct`` per plot (on a sample of 2 000),
pyproj's vectorised ``Geod.fwd`` alone, and the flat-earth converted measurement of the
simulation's ``PolarRadar`` (no ellipsoid). On the GeographicLib sample it also prints the
largest position error (distance and azimuth from the origin against GeographicLib's
``Inverse`` of its ``Direct`` end point) and the largest ``to_geodetic``/``to_local`` round
trip error.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable

import numpy as np
from geographiclib.geodesic import Geodesic

from mhtrack.models.geodesy import WGS84, LocalFrame, direct, polar_to_local
from mhtrack.models.sensors import PolarRadar

N = 100_000
SAMPLE = 2_000


def best_of(f: Callable[[], object], repeat: int = 5) -> float:
    """Fastest of ``repeat`` wall times (s)."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> int:
    frame = LocalFrame(46.8, 8.2)
    slat, slon = direct(46.8, 8.2, 250.0, 150e3)
    slat, slon = float(slat), float(slon)
    rng = np.random.default_rng(0)
    r = rng.uniform(1e3, 250e3, N)
    b = rng.uniform(0.0, 360.0, N)
    x, y = rng.uniform(-250e3, 250e3, (2, N))
    lat, lon = frame.to_geodetic(x, y)
    ve, vn = rng.uniform(-300, 300, (2, N))

    def per_plot(seconds: float, n: int = N) -> float:
        return 1e6 * seconds / n

    g = Geodesic.WGS84
    ref = per_plot(best_of(lambda: [g.Direct(slat, slon, b[i], r[i]) for i in range(SAMPLE)],
                           repeat=3), SAMPLE)
    z, _ = polar_to_local(frame, slat, slon, r[:SAMPLE], b[:SAMPLE], 80.0, 0.15)
    worst = 0.0
    for i in range(SAMPLE):
        d = g.Direct(slat, slon, b[i], r[i])
        inv = g.Inverse(46.8, 8.2, d["lat2"], d["lon2"])
        a = np.radians(inv["azi1"])
        worst = max(worst, float(np.hypot(z[i, 0] - inv["s12"] * np.sin(a),
                                          z[i, 1] - inv["s12"] * np.cos(a))))
    x2, y2 = frame.to_local(lat, lon)
    trip = float(np.hypot(x2 - x, y2 - y).max())
    fwd = per_plot(best_of(lambda: WGS84.fwd(np.full(N, slon), np.full(N, slat), b, r)))
    flat = PolarRadar(1, (0.0, 0.0), sigma_range=80.0, sigma_bearing_deg=0.15)
    rb = np.column_stack((r, b))
    rows = [
        ("polar_to_local (z and R)",
         best_of(lambda: polar_to_local(frame, slat, slon, r, b, 80.0, 0.15))),
        ("position only (direct + to_local)",
         best_of(lambda: frame.to_local(*direct(slat, slon, b, r)))),
        ("LocalFrame.to_local", best_of(lambda: frame.to_local(lat, lon))),
        ("LocalFrame.to_geodetic", best_of(lambda: frame.to_geodetic(x, y))),
        ("LocalFrame.velocity_to_local",
         best_of(lambda: frame.velocity_to_local(lat, lon, ve, vn))),
    ]
    print(f"{N} plots, site 150 km from the origin (46.8N 8.2E), ranges 1-250 km")
    print(f"  reference: geographiclib Geodesic.Direct (pure Python), per plot: {ref:8.2f} µs")
    print(f"  reference: pyproj Geod.fwd (vectorised), per plot:              {fwd:8.3f} µs")
    print(f"  reference: flat PolarRadar.convert (no ellipsoid), per plot:    "
          f"{per_plot(best_of(lambda: flat.convert(rb))):8.3f} µs")
    print(f"  accuracy: largest plot position error against geographiclib: {worst:.1e} m "
          f"({SAMPLE} plots); to_geodetic/to_local round trip: {trip:.1e} m ({N} points)")
    for label, t in rows:
        us = per_plot(t)
        print(f"  {label:36s} {us:8.3f} µs/plot  ({ref / us:6.1f}x faster than one "
              f"geographiclib Direct)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
