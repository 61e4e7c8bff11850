"""Plain MHT (known κ = 1e−9) on ``crossing`` under the caps' overload rule
(``mhtrack.mht.caps``): OSPA, Rcc and leaves per scan for other children-per-plot and
misses-per-tree limits than the shipped 4 and 2.

    PYTHONPATH=src python benchmarks/plain_mht_rule.py                  # seeds 1-5
    PYTHONPATH=src python benchmarks/plain_mht_rule.py --limits 4,2 8,2 --seeds 3

Each run is built as ``mhtrack run crossing --tracker mht`` builds it; only
``pruning.cap_per_plot``'s default limits are changed for the run.
"""

from __future__ import annotations

import argparse
import logging
import statistics


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limits", nargs="+", default=["2,1", "2,2", "4,1", "4,2", "4,4",
                                                    "8,2", "16,2"],
                    help="PER_PLOT,MISSES_PER_TREE pairs")
    ap.add_argument("--seeds", type=int, default=5, help="seeds 1 … N")
    a = ap.parse_args()
    from mhtrack.build import default_config
    from mhtrack.experiments.pipeline import run_scenario
    from mhtrack.mht import pruning
    from mhtrack.scenario import preset

    logging.disable(logging.WARNING)  # the caps' warnings
    sc = preset("crossing")
    shipped = pruning.cap_per_plot.__defaults__
    print("| per plot | misses per tree | mean OSPA (m) | per seed | Rcc | leaves/scan |")
    print("|---|---|---|---|---|---|")
    try:
        for pair in a.limits:
            k, m = (int(v) for v in pair.split(","))
            pruning.cap_per_plot.__defaults__ = (k, m)
            ospa, rcc, leaves = [], [], []
            for seed in range(1, a.seeds + 1):
                run = run_scenario(sc, seed, "mht", default_config(sc))
                s = run.summary()
                ospa.append(s["ospa_mean"])
                rcc.append(s["rcc"])
                leaves.append(statistics.median(t.n_leaves for t in run.run.stats))
            print(f"| {k} | {m} | {statistics.mean(ospa):.1f} | "
                  f"{', '.join(f'{v:.0f}' for v in ospa)} | {statistics.mean(rcc):.3f} | "
                  f"{statistics.mean(leaves):.0f} |", flush=True)
    finally:
        pruning.cap_per_plot.__defaults__ = shipped


if __name__ == "__main__":
    main()
