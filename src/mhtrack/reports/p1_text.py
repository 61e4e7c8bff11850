"""Markdown text of the P1 §3 reproduction: Table 3 (P1's rows and ours), the comparison
generated from the measured numbers, the settings and ``report.md``."""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from mhtrack.experiments.montecarlo import MonteCarloSpec
from mhtrack.experiments.p1 import P1Reproduction
from mhtrack.experiments.p1.constants import (
    MC_DIR,
    METRIC_BY_KEY,
    PAPER_SOURCE,
    RUN_KWARGS,
    TABLE3_METRICS,
    TABLE_FILE,
    TABLE_JSON,
    TRACKER_LABELS,
    TRACKER_SETTINGS,
    Metric,
    TrackerSettings,
    settings_file,
)
from mhtrack.reports.paired_text import paired_table, tally, verdict_list
from mhtrack.scenario import Scenario

KNOWN_REASONS = """\
Known reasons for differences (our choices and what P1 does not give):

* **Clutter rate.** P1 gives the clutter's spatial density (Table 2) but no clutter count;
  we draw λ = 40 clutter plots per scan (Poisson), our choice. Every number in the table
  depends on it.
* **Tavg.** P1's Tavg was measured on their machine with their code; ours is the mean
  wall-clock tracker time per scan of this Python implementation on this machine. Only
  the ratios between trackers are comparable, not the absolute values.
* **Plain MHT.** The plain MHT scores plots with P1's known constant clutter intensity
  κ = 1e−9 per m². Inside P1's tight clutter clumps (σ ≈ 30 m) the true clutter density
  is orders of magnitude higher, so the plain MHT over-confirms: it starts and keeps
  tracks on clutter, and its hypothesis trees grow until the hard caps act. This weighs
  on its OSPA and cardinality far more than P1's Figs. 5–6 suggest for their MHT, whose
  clutter level is unknown.
* **Tracker settings.** `--tracker-settings paper` runs P1's tracker: one
  constant-velocity model, the online output (the tracks as known at each scan), the
  clutter estimators with P1's steps only. `--tracker-settings best` (the default) runs
  ours: a two-model IMM, the history output (each confirmed track also at the scans
  between its first plot and its confirmation, `docs/mht.md`) and the estimators with our
  additions. P1 does not say which output it scores. `docs/reproduction.md` lists every
  parameter of both.
* **Metric definitions.** P1 does not define Rcc, Rmc, Rfg or L*; ours are in
  `docs/metrics.md`. In particular Rfg is the number of track breaks per target, counted
  per run over the 4 targets and averaged over runs — P1's values (0.02–0.04) suggest
  another normalisation (e.g. per track point), so Rfg compares only in ranking.
"""

def fmt(key: str, v: float) -> str:
    """``v`` as printed in the tables for metric ``key`` (``–`` for NaN)."""
    if not math.isfinite(v):
        return "–"
    return f"{v:.{METRIC_BY_KEY[key].digits}f}"



def _mean_pm_std(key: str, mean: float, std: float) -> str:
    return fmt(key, mean) + (f" ± {fmt(key, std)}" if math.isfinite(std) else "")


def _runs(n: int) -> str:
    return f"{n} run{'s' if n != 1 else ''}"


def table3_markdown(table: Mapping[str, Mapping[str, Mapping[str, float]]], runs: int,
                    row_label: str = "ours",
                    others: Sequence[tuple[str, Mapping[str, Any], int]] = ()) -> str:
    """Table 3 rows: for each tracker P1's row, ours (``row_label``, mean ± std over
    ``runs`` runs) and each of ``others`` (row label, its table, its runs)."""
    head = "| algorithm | source | " + " | ".join(m.label for m in TABLE3_METRICS) + " |"
    lines = [head, "|---|---|" + "---|" * len(TABLE3_METRICS)]
    for t, row in table.items():
        label = TRACKER_LABELS.get(t, t)
        paper = [fmt(m.key, row[m.key]["paper"]) for m in TABLE3_METRICS]
        lines.append(f"| {label} | P1 (as printed) | " + " | ".join(paper) + " |")
        for lab, tab, n in ((row_label, table, runs), *others):
            if t not in tab:
                continue
            cells = [_mean_pm_std(m.key, tab[t][m.key]["mean"], tab[t][m.key]["std"])
                     for m in TABLE3_METRICS]
            lines.append(f"| {label} | {lab} ({_runs(n)}) | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _others(repro: P1Reproduction) -> list[tuple[str, Mapping[str, Any], int]]:
    return [(TRACKER_SETTINGS[k].row_label, repro.other_tables[k], r.spec.runs)
            for k, r in repro.others.items()]


def table3_file(repro: P1Reproduction) -> str:
    """``table3.md``: Table 3 (P1's rows and ours) and the paired comparisons."""
    spec, st = repro.result.spec, repro.settings
    summary = repro.result.summary()
    ok = ", ".join(f"{TRACKER_LABELS.get(t, t)} {summary[t]['n_runs']}" for t in spec.trackers)
    return (
        f"# Table 3: performance metrics of the three algorithms (`{spec.scenario_name}`)\n\n"
        f"P1: {PAPER_SOURCE}. P1 gives no OSPA mean (–).\n\n"
        f"{st.row_label[0].upper()}{st.row_label[1:]} (`--tracker-settings {st.name}`): "
        f"{st.description}. Mean ± population std over the successful runs ({ok} of "
        f"{spec.runs}); Tavg is the tracker's wall-clock time per scan on this machine; OSPA "
        f"with c = {RUN_KWARGS['cutoff']:g} m, p = {RUN_KWARGS['order']:g}."
        + ("".join(f" Rows '{TRACKER_SETTINGS[k].row_label}': the study of "
                   f"`--tracker-settings {k}` in the same directory "
                   f"({TRACKER_SETTINGS[k].description})." for k in repro.others))
        + "\n\n" + table3_markdown(repro.table, spec.runs, st.row_label, _others(repro))
        + "\n## Paired comparisons\n\n" + PAIRED_NOTE + "\n\n"
        + paired_table(repro.paired, DIGITS, LABELS)
    )


PAIRED_NOTE = (
    "Run i of every tracker (and of both settings) simulates the same plots, so each row "
    "compares A and B run by run: the mean of the per-run differences A − B with its 95 % "
    "Student-t interval, the runs where both gave the same value, the runs where A is "
    "better / worse, a two-sided sign test and Wilcoxon signed-rank test. ↑: higher is "
    "better, ↓: lower is better. The verdict is read from the interval alone: `better` or "
    "`worse` when it excludes 0, else `no detectable difference` (`docs/reproduction.md`). "
    "Tavg is a wall-clock time and is not compared.")
DIGITS = {m.key: m.digits for m in TABLE3_METRICS}
LABELS = {m.key: m.label for m in TABLE3_METRICS}


# ---------------------------------------------------------------------------- comparison
def _against_paper(m: Metric, row: Mapping[str, float]) -> str:
    """Our mean with its 95 % interval, and where P1's value lies against it."""
    ours, paper, lo, hi = row["mean"], row["paper"], row.get("ci_low", math.nan), row.get(
        "ci_high", math.nan)
    if not math.isfinite(ours):
        return f"* {m.label}: no value of ours (no successful run); P1 {fmt(m.key, paper)}."
    text = f"* {m.label}: ours {fmt(m.key, ours)}{m.unit}"
    if m.key == "t_avg":
        return (text + f"; P1 {fmt(m.key, paper)}{m.unit} — another machine and code, not "
                "compared.")
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return text + f"; P1 {fmt(m.key, paper)}{m.unit} (no interval: fewer than 2 runs)."
    text += f" (95 % CI of the mean [{fmt(m.key, lo)}, {fmt(m.key, hi)}])"
    if lo <= paper <= hi:
        where = "inside it: consistent with P1"
    else:
        above = paper > hi
        ours_better = (not above) == m.higher_better
        where = (f"{'above' if above else 'below'} it: ours is "
                 f"{'better' if ours_better else 'worse'} than P1's")
    return text + f"; P1's {fmt(m.key, paper)}{m.unit} is {where}."


def compare_text(repro: P1Reproduction) -> str:
    """Markdown generated from the measured numbers: per tracker, each metric's mean and
    95 % interval against P1's value; then P1's claims between the trackers, each as the
    paired verdicts of :mod:`mhtrack.metrics.paired`."""
    lines: list[str] = []
    for t, row in repro.table.items():
        lines += [f"**{TRACKER_LABELS.get(t, t)}** ({repro.settings.row_label})", ""]
        for m in TABLE3_METRICS:
            if math.isfinite(row[m.key]["paper"]):
                lines.append(_against_paper(m, row[m.key]))
        lines.append("")
    lines += ["**P1's claims between the trackers, paired over our runs**", ""]
    by_pair: dict[tuple[str, str], list[Any]] = {}
    for c in repro.paired:
        by_pair.setdefault((c.a, c.b), []).append(c)
    for (a, b), cs in by_pair.items():
        lines.append(f"*{a} against {b}*: {tally(cs)}.")
        lines.append("")
        lines.append(verdict_list(cs))
    return "\n".join(lines)


# ---------------------------------------------------------------------------- report
def settings_text(spec: MonteCarloSpec, settings: TrackerSettings | None = None) -> str:
    from mhtrack.build import DEFAULT_CLUTTER_DENSITY, config_with, default_config

    sc = Scenario.from_dict(spec.scenario)
    d = spec.scenario
    cfg = config_with(default_config(sc), **spec.config)
    motion = (f"one constant-velocity model (σv = {cfg.sigma_v:g} m/s²)" if cfg.models is None
              else
              f"an IMM of two constant-velocity models (σv = {cfg.imm_sigma_v:g} and "
              f"{cfg.sigma_v:g} m/s²)")
    lines = ([] if settings is None else [
        f"* Tracker settings `{settings.name}` (`--tracker-settings {settings.name}`): "
        f"{settings.description}."]) + [
        f"* Scenario `{sc.name}`: {sc.description}",
        f"* Region x ∈ [{sc.region.as_tuple()[0]:g}, {sc.region.as_tuple()[1]:g}] m, "
        f"y ∈ [{sc.region.as_tuple()[2]:g}, {sc.region.as_tuple()[3]:g}] m; T = {sc.T:g} s; "
        f"scans {sc.first}–{sc.last} ({sc.n_scans}); P_D = {', '.join(f'{p:g}' for p in sc.pd)}.",
        f"* Targets ({len(sc.targets)}): " + "; ".join(
            f"{t.get('id')}: {_short(t)}" for t in d.get("targets", [])) + ".",
        "* Sensors: " + "; ".join(_short(s) for s in d.get("sensors", [])) + ".",
        f"* Clutter: {_short(d.get('clutter', {}))}; mean rate "
        f"λ = {sc.clutter_rate(sc.first):g} per scan.",
        f"* Trackers: {', '.join(spec.trackers)}; track-oriented MHT with "
        f"P_D = {cfg.p_detection:g}, new-target density {cfg.new_target_density:g} /m², "
        f"σw = {cfg.sigma_w:g} m, {motion}, N-scan pruning depth "
        f"{cfg.n_scan}, gate probability {cfg.gate_probability:g}; `mht` with the known "
        f"clutter density κ = {spec.run_kwargs.get('clutter_density', DEFAULT_CLUTTER_DENSITY):g} "
        "/m², `mht-gmm` / `mht-agmm` estimate it online (GMM with a fixed deletion threshold "
        "/ P1's adaptive GMM).",
        f"* Configuration changes from the defaults: `{json.dumps(spec.config)}`; "
        f"run_scenario keywords: `{json.dumps(spec.run_kwargs)}`.",
        f"* Monte-Carlo: {spec.runs} runs, base seed {spec.seed} (run i simulates with "
        "`run_seed(seed, i)`; every tracker sees the same plots in run i).",
    ]
    return "\n".join(lines)


def _short(d: Mapping[str, Any]) -> str:
    """Compact one-line JSON of a scenario sub-dict (numbers rounded)."""
    def r(v: Any) -> Any:
        if isinstance(v, float):
            return float(f"{v:.6g}")
        if isinstance(v, list):
            return [r(x) for x in v]
        if isinstance(v, dict):
            return {k: r(x) for k, x in v.items() if k != "region"}
        return v
    return "`" + json.dumps(r(dict(d)), separators=(", ", ": ")) + "`"


def report_markdown(repro: P1Reproduction, figures: Mapping[str, Path]) -> str:
    """``report.md``: settings, Table 3, the generated comparison, the known reasons for
    the differences and the figures (``figures``: key of :data:`FIGURES` → path)."""
    res = repro.result
    spec = res.spec
    st = repro.settings
    s = res.summary()
    failed = [(t, i) for t in spec.trackers for i in s[t]["failed"]]
    fig = figures
    rel = {k: os.path.relpath(p, repro.out_dir) for k, p in fig.items()}
    run0_check = []
    for t, sr in repro.run0.items():
        recs = [r for r in res.records.get(t, []) if r["run"] == 0]
        if recs and sr is not None:
            same = all(_same(sr.summary().get(k), recs[0].get(k))
                       for k in ("rcc", "rmc", "rfg", "l_avg", "ospa_mean"))
            run0_check.append(f"{TRACKER_LABELS.get(t, t)} "
                              f"{'matches' if same else 'DIFFERS FROM'} its stored run 0")
    parts = [
        f"# Reproduction of P1 §3 (Table 3, Figs. 2–6) — {st.row_label}",
        "",
        f"Generated by `mhtrack reproduce p1 --tracker-settings {st.name}`. Every number "
        "below is measured; every sentence comparing them is generated from them.",
        "",
        "## Settings",
        "",
        settings_text(spec, st),
        "",
        "## Table 3",
        "",
        f"P1's rows: {PAPER_SOURCE}. Rows '{st.row_label}': mean ± population std over "
        + ", ".join(f"{s[t]['n_runs']}" for t in spec.trackers)
        + f" successful runs of {', '.join(spec.trackers)} ({settings_file(TABLE_FILE, st)}, "
        f"{settings_file(TABLE_JSON, st)}; per-run files in "
        f"`{settings_file(MC_DIR, st)}/runs/`)"
        + "".join(f"; rows '{TRACKER_SETTINGS[k].row_label}': the study of "
                  f"`--tracker-settings {k}` found in the same directory" for k in repro.others)
        + ".",
        "",
        table3_markdown(repro.table, spec.runs, st.row_label, _others(repro)),
        "## Paired comparisons",
        "",
        PAIRED_NOTE,
        "",
        paired_table(repro.paired, DIGITS, LABELS),
    ]
    parts += ["## Hard caps, per run", "", caps_text(res, spec.trackers), ""]
    if failed or res.missing:
        parts += ["**Failed runs**: " + ", ".join(f"{t} run {i}" for t, i in failed)
                  + (" ; not run: " + ", ".join(f"{t} run {i}" for t, i in res.missing)
                     if res.missing else ""), ""]
    parts += [
        "## Where our numbers differ from P1's",
        "",
        compare_text(repro),
        KNOWN_REASONS,
        "## Figures",
        "",
        f"Fig. 2 — true trajectories (o start, x end):\n\n![Fig. 2]({rel['fig2']})",
        "",
        f"Fig. 3 — plots of run 0 (seed {repro.run0_seed}), clutter grey:\n\n"
        f"![Fig. 3]({rel['fig3']})",
        "",
        "Fig. 4 — tracks of run 0 of each tracker, recomputed with the runner's seed"
        + (f" ({'; '.join(run0_check)})" if run0_check else "")
        + f":\n\n![Fig. 4]({rel['fig4']})",
        "",
        f"Fig. 5 — OSPA per scan, mean over runs (band ± std):\n\n![Fig. 5]({rel['fig5']})",
        "",
        f"Fig. 6 — number of tracks per scan, mean ± std, and the true number:\n\n"
        f"![Fig. 6]({rel['fig6']})",
        "",
    ]
    return "\n".join(parts)


def caps_text(res: Any, trackers: Sequence[str]) -> str:
    """Per tracker: in how many runs the MHT's hard caps acted, how many scans per run
    (min / median / max) and each run's count (the full counts per cap are in
    ``table3.json``'s ``caps_per_run``)."""
    lines = []
    for t, rows in ((t, res.caps_per_run().get(t, [])) for t in trackers):
        label = TRACKER_LABELS.get(t, t)
        hit = [r for r in rows if r["scans"] > 0]
        if not hit:
            lines.append(f"* {label}: no cap acted in any of its {len(rows)} runs.")
            continue
        sc = sorted(r["scans"] for r in rows)
        names = sorted({k for r in hit for k in r if k not in ("run", "scans")})
        per_run = ", ".join(f"{r['run']}: {r['scans']}" for r in rows)
        lines.append(f"* {label}: caps acted in {len(hit)} of {len(rows)} runs "
                     f"({', '.join(names)}); scans with a cap acting per run min "
                     f"{sc[0]} / median {sc[len(sc) // 2]} / max {sc[-1]}. "
                     f"Run: scans — {per_run}.")
    return "\n".join(lines)


def _same(a: Any, b: Any) -> bool:
    fa, fb = _num(a), _num(b)
    if math.isnan(fa) and math.isnan(fb):
        return True
    return fa == fb


def _num(v: Any) -> float:
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan
