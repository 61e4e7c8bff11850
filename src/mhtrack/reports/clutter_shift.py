"""The outputs of ``reproduce clutter-shift`` (:mod:`mhtrack.experiments.clutter_shift`):
``results.json`` (parameters, per-method means, per-scan clutter error, paired
comparisons), ``report.md`` (every comparison sentence generated from the numbers) and
``clutter_error.png`` (the true field at four scans and the clutter error per scan)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mhtrack.experiments.clutter_shift import (
    METRICS,
    PAIRS,
    ClutterShiftStudy,
    mean_iae_per_scan,
)
from mhtrack.io.atomic import atomic_write
from mhtrack.io.jsonsafe import to_jsonable
from mhtrack.reports.paired_text import paired_table, tally, verdict_list

RESULTS_FILE = "results.json"
REPORT_FILE = "report.md"
FIGURE_FILE = "clutter_error.png"
SNAPSHOT_SCANS = (1, 35, 60, 90)


@dataclass
class ClutterShiftReport:
    """What :func:`write_clutter_shift_report` wrote."""

    results_path: Path
    report_path: Path
    figure_path: Path | None
    paths: list[Path] = field(default_factory=list)


def method_means(study: ClutterShiftStudy) -> dict[str, dict[str, float]]:
    """Per method, the mean over its runs of each metric of :data:`METRICS` and ``t_avg``."""
    out: dict[str, dict[str, float]] = {}
    for m, recs in study.records.items():
        row = {}
        for k in (*METRICS, "t_avg"):
            v = np.array([math.nan if r.get(k) is None else float(r[k]) for r in recs])
            v = v[np.isfinite(v)]
            row[k] = float(v.mean()) if v.size else math.nan
        row["n_runs"] = len(recs)
        row["runs_with_caps"] = sum(1 for r in recs if r.get("caps"))
        out[m] = row
    return out


def results_dict(study: ClutterShiftStudy) -> dict[str, Any]:
    """``results.json``: parameters, means, clutter error per scan, paired comparisons."""
    return {"params": study.params, "means": method_means(study),
            "iae_per_scan": {m: mean_iae_per_scan(r) for m, r in study.records.items()},
            "failed": sorted(study.errors),
            "paired": [c.to_dict() for c in study.paired]}


def _f(v: float, d: int) -> str:
    return "–" if not math.isfinite(v) else f"{v:.{d}f}"


def means_table(study: ClutterShiftStudy) -> str:
    means = method_means(study)
    keys = list(METRICS)
    lines = ["| method | what it is | runs | " + " | ".join(METRICS[k][0] for k in keys)
             + " | Tavg (s) | runs with caps |",
             "|---|---|---|" + "---|" * len(keys) + "---|---|"]
    for m, row in means.items():
        lines.append(f"| {m} | {study.params['method_descriptions'][m]} | {row['n_runs']} | "
                     + " | ".join(_f(row[k], METRICS[k][2]) for k in keys)
                     + f" | {_f(row['t_avg'], 3)} | {row['runs_with_caps']} |")
    return "\n".join(lines) + "\n"


P1_GMM, P1_AGMM = "gmm, P1's steps only", "agmm, P1's steps only"


def analysis_text(ab: Any) -> str:
    """The *Why* section from an :class:`~mhtrack.experiments.clutter_shift_ablation.
    Ablation`: what each switch does to the AGMM's clutter error, then the table and the
    verdicts — all from the numbers."""
    from mhtrack.experiments.clutter_shift_ablation import ablation_markdown

    m = {k: float(np.mean(v)) for k, v in ab.iae.items()}
    c = {x.a: x for x in ab.paired}

    def v(k: str) -> str:
        x = c.get(k)
        if x is None:
            return ""
        if x.verdict == "no detectable difference":
            return f" (no detectable difference from gmm at n = {x.n})"
        return f" ({x.verdict} than gmm, n = {x.n})"

    lines = [
        f"Each estimator alone, fed every scan of runs 0–{ab.runs - 1} of this study (no "
        "tracker), one design choice switched at a time; clutter error ∫|κ̂ − κ| averaged "
        "over the scans:", "",
        f"* GMM (P1's MHT-GMM): {m['gmm']:.2f}; AGMM (P1's MHT-AGMM, with our BIC test): "
        f"{m['agmm']:.2f}{v('agmm')}.",
        f"* Without our BIC test of the number of components (`bic=False`, P1's eq. 12 "
        f"alone): {m['agmm, bic=False']:.2f}{v('agmm, bic=False')}. The same test given to "
        f"the GMM: {m['gmm, bic=True']:.2f}{v('gmm, bic=True')}.",
        f"* P1 eq. 12's mass threshold 0.92 raised to 0.99: {m['agmm, mass=0.99']:.2f}"
        f"{v('agmm, mass=0.99')}; with neither: {m['agmm, mass=0.99, bic=False']:.2f}"
        f"{v('agmm, mass=0.99, bic=False')}.",
        f"* P1's steps only (one fit per scan from fresh seeds, no background component, no "
        f"contrast test): GMM {m[P1_GMM]:.2f}, AGMM {m[P1_AGMM]:.2f}.",
        "", ablation_markdown(ab)]
    return "\n".join(lines)


def report_markdown(study: ClutterShiftStudy, figure: Path | None,
                    analysis: str = "") -> str:
    """``report.md``: parameters, means, paired comparisons with their sentences, the
    answer to P1's claim generated from the AGMM–GMM verdicts, and ``analysis`` (a
    measured explanation, when given)."""
    p = study.params
    digits = {k: d for k, (_, _, d) in METRICS.items()}
    labels = {k: lab for k, (lab, _, _) in METRICS.items()}
    by_pair: dict[tuple[str, str], list[Any]] = {}
    for c in study.paired:
        by_pair.setdefault((c.a, c.b), []).append(c)
    parts = [
        f"# Clutter shift: {', '.join(p['methods'])} on `{p['scenario']}`",
        "",
        f"Generated by `mhtrack reproduce clutter-shift`. Scenario `{p['scenario']}` "
        + ("(`docs/clutter.md`, *A clutter that changes*): P1's four crossing targets in "
           "clutter whose components appear, vanish, split, merge and drift. "
           if p["scenario"] == "crossing-changing" else "(`docs/scenarios.md`). ")
        + f"{p['runs']} paired runs (base seed {p['seed']}; run i simulates the same plots "
        f"for every method), tracker defaults with `{json.dumps(p['config'])}`, output "
        f"`{p['output']}`, OSPA c = {p['cutoff']:g} m, p = {p['order']:g}. The clutter error "
        f"is ∫|κ̂_k − κ_k| over the region on a {p['resolution']}² grid, after every scan, "
        "of the intensity the tracker's own estimator holds, averaged over the scans.",
        "",
        "## Means over runs",
        "",
        means_table(study),
    ]
    if study.errors:
        parts += [f"**Failed or missing jobs**: {', '.join(sorted(study.errors))}.", ""]
    parts += [
        "## Paired comparisons",
        "",
        "A − B per run; mean with its 95 % t interval; identical runs; sign and Wilcoxon "
        "tests. The verdict is read from the interval (↑ higher is better, ↓ lower).",
        "",
        paired_table(study.paired, digits, labels),
    ]
    for (a, b), cs in by_pair.items():
        parts += [f"**{a} against {b}**: {tally(cs)}.", "", verdict_list(cs)]
    agmm = by_pair.get(("agmm", "gmm"), [])
    if agmm:
        parts += ["## P1's claim on a clutter that changes", "", claim_sentence(agmm), ""]
    if analysis:
        parts += ["## Why", "", analysis, ""]
    if figure is not None:
        parts += ["## Figure", "",
                  f"True clutter intensity at scans {', '.join(map(str, SNAPSHOT_SCANS))} "
                  "and the clutter error per scan, mean over runs:", "",
                  f"![clutter error]({figure.name})", ""]
    return "\n".join(parts)


def claim_sentence(agmm_vs_gmm: list[Any]) -> str:
    """Whether AGMM beats GMM here, from the verdicts: on the clutter error and on the
    tracking metrics."""
    err = [c for c in agmm_vs_gmm if c.metric == "iae_mean"]
    trk = [c for c in agmm_vs_gmm if c.metric != "iae_mean"]
    n = agmm_vs_gmm[0].n
    better = [c.metric for c in agmm_vs_gmm if c.verdict == "better"]
    worse = [c.metric for c in agmm_vs_gmm if c.verdict == "worse"]
    if better and not worse:
        head = "AGMM beats GMM here"
    elif worse and not better:
        head = "AGMM does not beat GMM here: it is worse"
    elif better and worse:
        head = ("AGMM does not beat GMM overall here: it is better on some metrics, worse "
                "on others")
    else:
        head = f"AGMM does not beat GMM here either: no detectable difference at n = {n}"
    return (f"{head} (clutter error: {err[0].verdict if err else '–'}; tracking metrics: "
            f"{tally(trk)}). Better on: {', '.join(better) or 'none'}; worse on: "
            f"{', '.join(worse) or 'none'}.")


def _figure(study: ClutterShiftStudy, scenario: Any, path: Path) -> Path:
    from matplotlib.figure import Figure

    from mhtrack.plotting.scene import save_figure

    fig = Figure(figsize=(15, 3.6))
    axes = fig.subplots(1, len(SNAPSHOT_SCANS) + 1)
    grid, _ = scenario.region.grid(120)
    x0, x1, y0, y1 = scenario.region.as_tuple()
    for ax, k in zip(axes, SNAPSHOT_SCANS, strict=False):
        kk = min(max(k, scenario.first), scenario.last)
        z = scenario.clutter.intensity(grid, kk).reshape(120, 120)
        ax.imshow(z, origin="lower", extent=(x0, x1, y0, y1), cmap="viridis")
        ax.set_title(f"true κ, scan {kk}")
        ax.set_xticks([])
        ax.set_yticks([])
    ax = axes[-1]
    for m, recs in study.records.items():
        v = mean_iae_per_scan(recs)
        if v:
            ax.plot(range(scenario.first, scenario.first + len(v)), v, label=m)
    ax.set_xlabel("scan")
    ax.set_ylabel("∫|κ̂ − κ| (plots/scan)")
    ax.legend(fontsize=8)
    return save_figure(fig, path, dpi=110)


def write_clutter_shift_report(study: ClutterShiftStudy, scenario: Any = None,
                               ablation: Any = None) -> ClutterShiftReport:
    """Write ``results.json``, ``report.md`` (with the *Why* section of ``ablation`` when
    given) and (with ``scenario``) the figure."""
    out = study.out_dir
    js = results_dict(study)
    if ablation is not None:
        js["ablation"] = ablation.to_dict()
    res = atomic_write(out / RESULTS_FILE, json.dumps(to_jsonable(js), indent=1) + "\n")
    fig = _figure(study, scenario, out / FIGURE_FILE) if scenario is not None else None
    analysis = analysis_text(ablation) if ablation is not None else ""
    rep = atomic_write(out / REPORT_FILE, report_markdown(study, fig, analysis))
    return ClutterShiftReport(res, rep, fig, [res, rep, *([fig] if fig else []),
                                              out / "jobs"])


__all__ = ["PAIRS", "ClutterShiftReport", "claim_sentence", "results_dict",
           "write_clutter_shift_report"]
