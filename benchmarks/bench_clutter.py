"""Speed of the online clutter estimators (one ``update`` + ``intensity`` per scan).

Run: ``python benchmarks/bench_clutter.py``. On ``crossing`` (40 clutter plots per scan in
P1's four clumps, window of 5 scans) it times ``GMMClutter`` and ``AGMMClutter`` per scan and
prints the ratio against scikit-learn's ``GaussianMixture`` fitted to the same pooled plots
each scan (same number of components, k-means initialisation, one init) — a reference
measured in the same run. Also a 10 000-plot burst scan.
"""

from __future__ import annotations

import sys
import time

import numpy as np
from sklearn.mixture import GaussianMixture

from mhtrack.clutter import AGMMClutter, GMMClutter
from mhtrack.records import Scan
from mhtrack.scenario import preset, simulate


def per_scan(est: object, scans: list[Scan]) -> np.ndarray:
    out = []
    for s in scans:
        t0 = time.perf_counter()
        est.update(s, None)  # type: ignore[attr-defined]
        est.intensity(s.z)  # type: ignore[attr-defined]
        out.append(time.perf_counter() - t0)
    return np.array(out)


def main() -> int:
    scans = list(simulate(preset("crossing"), seed=1).plots.scans())
    ref = []
    for k in range(len(scans)):
        pooled = np.concatenate([s.z for s in scans[max(0, k - 4) : k + 1]])
        t0 = time.perf_counter()
        gm = GaussianMixture(8, reg_covar=100.0, random_state=0).fit(pooled)
        gm.score_samples(scans[k].z)
        ref.append(time.perf_counter() - t0)
    r = float(np.median(ref))
    print(f"crossing, {len(scans)} scans, ~44 plots/scan, window 5: median per scan")
    print(f"  scikit-learn GaussianMixture(8) refit: {1e3 * r:.2f} ms (reference)")
    for cls in (GMMClutter, AGMMClutter):
        t = per_scan(cls(), scans)
        m = float(np.median(t))
        print(f"  {cls.__name__:12s} update+intensity: {1e3 * m:.2f} ms "
              f"(p90 {1e3 * np.quantile(t, 0.9):.2f}), ratio to sklearn {m / r:.2f}x")
    rng = np.random.default_rng(0)
    for label, z in (
        ("uniform", rng.uniform(-4000, 4000, (10_000, 2))),
        ("half in one clump", np.concatenate((rng.uniform(-4000, 4000, (5000, 2)),
                                              rng.normal(0, 50, (5000, 2))))),
    ):
        t0 = time.perf_counter()
        gm = GaussianMixture(8, reg_covar=100.0, random_state=0).fit(z)
        gm.score_samples(z)
        r = time.perf_counter() - t0
        est = AGMMClutter(window=1)
        est.update(Scan.from_positions(0, 0.0, z[:100]), None)
        t0 = time.perf_counter()
        est.update(Scan.from_positions(1, 1.0, z), None)
        est.intensity(z)
        t = time.perf_counter() - t0
        print(f"  10 000-plot burst ({label}): AGMMClutter {t:.3f} s (subsampled "
              f"{est.n_subsampled_} plots), sklearn GaussianMixture(8) on all {r:.3f} s, "
              f"ratio {t / r:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
