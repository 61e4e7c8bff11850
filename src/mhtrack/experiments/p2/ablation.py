"""Why the modified 3/4 logic starts ~20 false tracks per window and the modified Hough
~0.4 (P2 Figs. 12–15 show them alike): each initiator with one of its parameters switched,
on the same fused windows (σr = 20 m, λ = 50 per radar, θ = 20°, P2's other settings).

``python -m mhtrack.experiments.p2.ablation RUNS [best|paper]`` prints a Markdown table:
p_true, false tracks per window, p_false (P2's reading) and tracks per window. Measured
(20 runs, docs/reproduction.md): the gap is P2's two thresholds — the logic starts on 3
plots of 4 scans, the Hough on 4 votes of 4 — not the transform: with the same M the two
agree.
"""

from __future__ import annotations

import sys
from typing import Any

import numpy as np

from mhtrack.experiments.jobs import run_seed
from mhtrack.experiments.p2.constants import INITIATOR_PARAMS, RATE0, SIGMA0, THETA0
from mhtrack.experiments.p2.jobs import _initiable, _score, fused_run, p2_scenario
from mhtrack.initiation import Window
from mhtrack.initiation.hough import HoughInitiator
from mhtrack.initiation.logic import LogicInitiator


def variants(region: tuple[float, ...], settings: str = "best") -> dict[str, Any]:
    """The initiators compared: the study's two, and each with one threshold changed."""
    v: dict[str, Any] = {"v_min": 50.0, "v_max": 400.0}
    h: dict[str, Any] = {**v, "region": region, "angle_limit_deg": THETA0,
                         **INITIATOR_PARAMS[settings].get("modified-hough", {})}
    lg: dict[str, Any] = {**v, "angle_limit_deg": THETA0}
    return {
        "modified logic, 3/4, gate 300 m (study)": LogicInitiator(gate_radius=300.0, **lg),
        "modified logic, 4/4": LogicInitiator(gate_radius=300.0, min_plots=4, **lg),
        "modified logic, 3/4, gate 100 m": LogicInitiator(gate_radius=100.0, **lg),
        "modified Hough, 4 votes (study)": HoughInitiator(modified=True, **h),
        "modified Hough, 3 votes": HoughInitiator(modified=True, votes=3, **h),
        "modified Hough, 3 votes, Nθ = Nρ = 30": HoughInitiator(
            modified=True, votes=3, n_theta=30, n_rho=30, **h),
    }


def ablation(runs: int, settings: str = "best", seed: int = 0) -> dict[str, dict[str, float]]:
    """Each variant's p_true, false tracks per window, p_false, tracks per window over
    ``runs`` runs (run r: ``run_seed(seed, r, "words")``, as the study)."""
    sc = p2_scenario(SIGMA0, RATE0)
    inits = variants(sc.region.as_tuple(), settings)
    acc = {k: np.zeros(3) for k in inits}
    n_t = n_w = 0
    for r in range(runs):
        for raw, win in fused_run(sc, run_seed(seed, r, "words"), settings).windows(4):
            w = Window.from_scans(win)
            tg = _initiable(raw)
            n_t += len(tg)
            n_w += 1
            for k, ini in inits.items():
                acc[k] += _score(w, ini.initiate(w).flat, tg)
    return {k: {"p_true": f / n_t, "false_per_window": fa / n_w,
                "p_false": fa / (fa + f) if fa + f else float("nan"),
                "tracks_per_window": n / n_w} for k, (f, fa, n) in acc.items()}


def main(argv: list[str]) -> None:
    runs = int(argv[0]) if argv else 20
    settings = argv[1] if len(argv) > 1 else "best"
    res = ablation(runs, settings)
    print(f"{runs} runs, settings {settings}\n")
    print("| initiator | p_true | false/window | p_false | tracks/window |\n|---|---|---|---|---|")
    for k, m in res.items():
        print(f"| {k} | {m['p_true']:.3f} | {m['false_per_window']:.2f} | "
              f"{m['p_false']:.3f} | {m['tracks_per_window']:.2f} |")


if __name__ == "__main__":  # pragma: no cover
    main(sys.argv[1:])
