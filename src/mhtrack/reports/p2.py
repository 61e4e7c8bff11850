"""The outputs of ``reproduce p2`` in its directory: ``results.json`` (the aggregated
numbers), ``tables.md``, ``report.md`` (:mod:`mhtrack.reports.p2_text`) and P2's figures
``fig3_ptrue_theta.png``, ``fig4_pfalse_theta.png`` (θ curves), ``fig2_clustering.png``
and ``fig12_15_initiated.png`` (run 0; a failure of one of these two leaves
``<figure>.error.txt`` instead, and the study is kept)."""

from __future__ import annotations

import json
import traceback
from pathlib import Path

from mhtrack.experiments.p2 import P2Reproduction
from mhtrack.experiments.p2.aggregate import curve_for
from mhtrack.experiments.p2.constants import (
    ADAPTIVE_LABELS,
    FIGURES,
    JOBS_DIR,
    METHOD_LABELS,
    MODIFIED_HOUGH_LABELS,
    RATE0,
    REPORT_FILE,
    RESULTS_FILE,
    SIGMA0,
    TABLES_FILE,
    THETA0,
)
from mhtrack.experiments.p2.examples import FIGURE_NUMBERS, fig2_example, fig12_15_example
from mhtrack.io.atomic import atomic_write
from mhtrack.plotting.scene import save_figure
from mhtrack.reports.p2_text import report_markdown, tables_markdown


def p2_paths(out_dir: Path) -> list[Path]:
    """Every output of ``reproduce p2`` in ``out_dir``: figures, tables, report, results,
    job directory."""
    return [out_dir / f for f in (*FIGURES.values(), TABLES_FILE, REPORT_FILE, RESULTS_FILE,
                                  JOBS_DIR)]


def _theta_figures(repro: P2Reproduction) -> None:
    from mhtrack.plotting.theta import theta_curves_figure

    res, out = repro.results, repro.out_dir
    sig = sorted({c["sigma_range"] for c in res["curves"] if c["clutter_rate"] == RATE0})
    rat = sorted({c["clutter_rate"] for c in res["curves"] if c["sigma_range"] == SIGMA0})
    for key, name, points, label, title in (
        ("p_true", "fig3", [(s, RATE0) for s in sig], lambda s, r: f"σr = {s:g} m",
         f"P2 Fig. 3: p_true of modified 3/4 logic, λ = {RATE0:g} ({repro.runs} runs)"),
        ("p_false", "fig4", [(SIGMA0, r) for r in rat], lambda s, r: f"λ = {r:g}",
         f"P2 Fig. 4: p_false of modified 3/4 logic, σr = {SIGMA0:g} m ({repro.runs} runs)"),
    ):
        curves = {}
        for s, r in points:
            c = curve_for(res, s, r)
            if c is not None:
                curves[label(s, r)] = [float("nan") if v is None else v for v in c[key]]
        fig = theta_curves_figure(res["thetas_deg"], curves, ylabel=key, title=title,
                                  theta_mark=THETA0, mark_label="θ = 20° (P2's choice)")
        save_figure(fig, out / FIGURES[name], dpi=110)


def _fig2(seed: int, path: Path, settings: str) -> None:
    from mhtrack.plotting.initiation import clustering_figure

    ex = fig2_example(seed, settings)
    fig = clustering_figure(ex.scan, ex.fused, ex.truth_xy,
                            title=f"{ex.scenario}, scan {ex.scan.index}")
    save_figure(fig, path, dpi=100, tight=False)


def _fig12_15(seed: int, path: Path, settings: str) -> None:
    from mhtrack.plotting.initiation import initiated_tracks_figure

    ex = fig12_15_example(seed, settings)
    s = ex.fused.scans
    labels = {**METHOD_LABELS, "modified-hough": MODIFIED_HOUGH_LABELS[settings]}
    titles = {m: f"P2 Fig. {n}: {labels[m]}" for m, n in FIGURE_NUMBERS.items()}
    fig = initiated_tracks_figure(
        ex.fused, ex.tracks, ex.truth_xy, titles,
        title=f"multiradar, run 0, scans {s[0]}–{s[-1]}, σr = 20 m, λ = 50, θ = 20°, "
              f"{ADAPTIVE_LABELS[settings]} (settings: {settings})")
    save_figure(fig, path, dpi=100)


def write_p2_report(repro: P2Reproduction) -> list[Path]:
    """Write every output of the study ``repro`` into its directory (module docstring);
    returns :func:`p2_paths`."""
    out, res = repro.out_dir, repro.results
    atomic_write(out / RESULTS_FILE, json.dumps(res, indent=1) + "\n")
    _theta_figures(repro)
    for fn, name in ((_fig2, "fig2"), (_fig12_15, "fig12_15")):
        try:
            fn(repro.seed, out / FIGURES[name], res.get("settings", "best"))
        except Exception:  # a figure must not lose the study
            atomic_write(out / f"{FIGURES[name]}.error.txt", traceback.format_exc())
    atomic_write(out / TABLES_FILE, tables_markdown(res))
    atomic_write(out / REPORT_FILE, report_markdown(res, repro.runs, repro.seed,
                                                    repro.wall_seconds if repro.computed
                                                    else None))
    return p2_paths(out)
