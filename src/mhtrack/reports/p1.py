"""The outputs of ``reproduce p1`` in its directory: the Monte-Carlo report in
``montecarlo/`` (:mod:`mhtrack.reports.montecarlo`), ``table3.md`` (our Table 3 beside
P1's) and ``table3.json`` (the same numbers unrounded), P1's Figs. 2–6
(``fig2_truth.png`` … ``fig6_cardinality.png``; Figs. 3–4 show run 0) and ``report.md``."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

from mhtrack.experiments.p1 import P1Reproduction
from mhtrack.experiments.p1.constants import (
    FIGURES,
    PAPER_SOURCE,
    REPORT_FILE,
    TABLE_FILE,
    TABLE_JSON,
    TRACKER_LABELS,
    TRACKER_SETTINGS,
    settings_file,
)
from mhtrack.io.atomic import atomic_write
from mhtrack.io.jsonsafe import to_jsonable
from mhtrack.plotting.scene import save_figure
from mhtrack.reports.montecarlo import write_montecarlo_report
from mhtrack.reports.p1_text import report_markdown, table3_file


@dataclass
class P1Report:
    """What :func:`write_p1_report` wrote."""

    table_md: str
    table_path: Path
    report_path: Path
    figures: dict[str, Path] = field(default_factory=dict)
    paths: list[Path] = field(default_factory=list)


def _figures(repro: P1Reproduction) -> dict[str, Path]:
    from mhtrack.plotting.p1 import mean_curves_figure, tracks_panels_figure
    from mhtrack.plotting.scene import plot_scene  # Figs. 2–3

    spec, sim = repro.result.spec, repro.simulation
    name = spec.scenario_name
    paths = {k: repro.out_dir / settings_file(v, repro.settings) for k, v in FIGURES.items()}
    save_figure(plot_scene(truth=sim.truth, title=f"Fig. 2 — {name}: target trajectories"),
                paths["fig2"])
    save_figure(plot_scene(plots=sim.plots, title=f"Fig. 3 — {name}: plots with clutter "
                           f"(run 0, seed {repro.run0_seed})"), paths["fig3"])
    tracks = {TRACKER_LABELS.get(t, t): (None if repro.run0.get(t) is None
                                         else repro.run0[t].run.tracks)
              for t in spec.trackers}
    save_figure(tracks_panels_figure(sim.truth, tracks,
                              title=f"Fig. 4 — {name}: tracks of the three algorithms"),
         paths["fig4"], dpi=130)
    summ = repro.result.summary()
    curves = {TRACKER_LABELS.get(t, t): summ[t]["per_scan"] for t in spec.trackers
              if summ[t]["per_scan"]["scans"]}
    cutoff = spec.run_kwargs.get("cutoff", 500.0)
    save_figure(mean_curves_figure(
        curves, "ospa", band_alpha=0.12,
        ylabel=f"OSPA (m), c = {cutoff:g}, p = {spec.run_kwargs.get('order', 2.0):g}",
        title=f"Fig. 5 — OSPA distance, mean over {spec.runs} runs (band ± std)"),
        paths["fig5"], dpi=130)
    save_figure(mean_curves_figure(
        curves, "cardinality", band_alpha=0.15, truth_key="cardinality_true",
        ylabel="number of targets / tracks",
        title=f"Fig. 6 — cardinality estimate, mean (band ± std) over {spec.runs} runs"),
        paths["fig6"], dpi=130)
    return paths


def write_p1_report(repro: P1Reproduction) -> P1Report:
    """Write every output of the study ``repro`` (module docstring)."""
    out_dir, spec, st = repro.out_dir, repro.result.spec, repro.settings
    write_montecarlo_report(repro.result)
    summary = repro.result.summary()
    n_ok = {t: summary[t]["n_runs"] for t in spec.trackers}
    table_md = table3_file(repro)
    table_path = atomic_write(out_dir / settings_file(TABLE_FILE, st), table_md)
    js = {"source": PAPER_SOURCE, "runs": spec.runs, "seed": spec.seed,
          "tracker_settings": st.name, "settings_description": st.description,
          "config": dict(spec.config), "run_kwargs": dict(spec.run_kwargs),
          "n_runs_ok": n_ok, "table": repro.table,
          "other_settings": {k: {"description": TRACKER_SETTINGS[k].description,
                                 "runs": r.spec.runs, "table": repro.other_tables[k]}
                             for k, r in repro.others.items()},
          "paired": [c.to_dict() for c in repro.paired],  # NaN (no value) written as null
          "caps_per_run": repro.result.caps_per_run()}
    json_path = atomic_write(out_dir / settings_file(TABLE_JSON, st),
                             json.dumps(to_jsonable(js), indent=1) + "\n")
    figures = _figures(repro)
    report_path = atomic_write(out_dir / settings_file(REPORT_FILE, st),
                               report_markdown(repro, figures))
    paths = [table_path, json_path, report_path, *figures.values(), repro.result.out_dir]
    return P1Report(table_md, table_path, report_path, figures, paths)
