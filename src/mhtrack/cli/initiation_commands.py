"""``cluster`` and ``initiate``: multi-radar plot fusion and track initiation (P2).

Both simulate ``--runs`` independent runs (seeds derived from ``--seed``), call
:mod:`mhtrack.experiments.initiation_runs`, score with :mod:`mhtrack.metrics.initiation`
and print; ``--out`` (formerly ``--figure``) is drawn by :mod:`mhtrack.reports.initiation`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from mhtrack.cli.common import echo_json, load_scenario_arg, out_option, scenario_options
from mhtrack.cli.terminal import show_progress
from mhtrack.names import CLUSTER_METHODS, INITIATION_FUSIONS, INITIATORS


def _common(f: Any) -> Any:
    opts = [
        click.option("--runs", type=click.IntRange(min=1), default=100, show_default=True,
                     help="Independent Monte-Carlo runs (seeds derived from --seed)."),
        click.option("--weighting", type=click.Choice(["mean", "information"]),
                     default="mean", show_default=True,
                     help="Fused plot: cluster mean (P2) or information-weighted."),
        click.option("--json", "as_json", is_flag=True, help="Print one JSON object."),
        out_option("figure", "--figure", type=click.Path(dir_okay=False, path_type=Path),
                   help="Also draw the first run to FILE (PNG/PDF/SVG)."),
    ]
    for opt in reversed(opts):
        f = opt(f)
    return f


def _rate(sc: Any) -> float:
    return float(sc.clutter_rate(sc.first))


@click.command()
@scenario_options
@click.option("--method", type=click.Choice(CLUSTER_METHODS), default="adaptive",
              show_default=True,
              help="Adaptive K-means (P2 §1.2) or K-means from random plots with k = the "
              "number of targets seen (P2 Fig. 2a).")
@_common
def cluster(scenario: str, seed: int, clutter: str | None, clutter_rate: float | None,
            pd: float | None, scans: int | None, method: str, runs: int, weighting: str,
            as_json: bool, figure: Path | None) -> None:
    """Fuse the plots of every scan of SCENARIO by clustering and score the clusters:
    k_correct_rate (share of scans with as many clusters as targets seen), mean distance
    of the fused plots to the truth, cluster purity, time per scan."""
    from mhtrack.experiments.initiation_runs import run_clustering
    from mhtrack.metrics.initiation import (
        cluster_purity,
        clustering_metrics,
        fused_plot_errors,
    )

    sc = load_scenario_arg(scenario, clutter, clutter_rate, pd, scans)
    out = run_clustering(sc, method, runs=runs, seed=seed, weighting=weighting,
                         progress=show_progress())
    m = clustering_metrics(
        [len(c.fused) for c in out],
        [len(c.truth) for c in out],
        [fused_plot_errors(c.fused, c.truth) for c in out],
        [cluster_purity(c.labels, c.origin) for c in out],
        [c.seconds for c in out],
    )
    d = {"scenario": sc.name, "method": method, "runs": runs, "seed": seed,
         "clutter_rate": _rate(sc), "weighting": weighting, **m.to_dict()}
    if figure is not None:
        from mhtrack.plotting.scene import save_figure
        from mhtrack.reports.initiation import clustering_figure_for

        save_figure(clustering_figure_for(sc, seed), figure)
    if as_json:
        echo_json(d)
        return
    click.echo(
        f"{sc.name} ({method} K-means, λ = {d['clutter_rate']:g} per radar, {runs} runs, "
        f"{m.n_scans} scans)\n"
        f"  k_correct_rate   {m.k_correct_rate:.4f}\n"
        f"  clusters/scan    {m.mean_clusters:.2f} (targets seen {m.mean_targets:.2f})\n"
        f"  fused error      {m.fused_error_mean:.1f} m\n"
        f"  purity           {m.purity:.4f}\n"
        f"  time/scan        {1e3 * m.t_scan:.2f} ms"
    )


@click.command()
@scenario_options
@click.option("--method", type=click.Choice(INITIATORS),
              default="modified-logic", show_default=True, help="Initiator (P2 §2, §3.2).")
@click.option("--fusion", type=click.Choice(INITIATION_FUSIONS),
              default="adaptive-kmeans", show_default=True,
              help="Plot fusion before initiation.")
@click.option("--theta", "theta_deg", type=click.FloatRange(0, 180), default=20.0,
              show_default=True, help="Angle limit θ (degrees) of the modified methods (P2).")
@click.option("--gate-radius", type=click.FloatRange(min=0, min_open=True), default=300.0,
              show_default=True, help="Logic position gate r (m) (P2).")
@click.option("--v-min", type=click.FloatRange(min=0), default=50.0, show_default=True,
              help="Velocity gate lower bound (m/s) (ours).")
@click.option("--v-max", type=click.FloatRange(min=0, min_open=True), default=400.0,
              show_default=True, help="Velocity gate upper bound (m/s) (ours).")
@_common
def initiate(scenario: str, seed: int, clutter: str | None, clutter_rate: float | None,
             pd: float | None, scans: int | None, method: str, fusion: str,
             theta_deg: float, gate_radius: float, v_min: float, v_max: float, runs: int,
             weighting: str, as_json: bool, figure: Path | None) -> None:
    """Start tracks on every 4-scan window of SCENARIO and score them (P2's metrics):
    p_true, p_false, false tracks per run, time per window."""
    from mhtrack.build import make_initiator
    from mhtrack.experiments.initiation_runs import run_initiation
    from mhtrack.metrics.initiation import initiable_targets, initiation_metrics, track_targets

    if v_min >= v_max:
        raise click.BadParameter(f"--v-min ({v_min}) must be below --v-max ({v_max})")
    sc = load_scenario_arg(scenario, clutter, clutter_rate, pd, scans)
    n_scans = len(sc.scan_indices())
    if n_scans < 4:
        raise click.BadParameter(
            f"the initiators work on 4-scan windows; {sc.name} has {n_scans} scan(s)",
            param_hint="'--scans' or the scenario's scans")
    params: dict[str, Any] = {"v_min": v_min, "v_max": v_max}
    if method.endswith("logic"):
        params["gate_radius"] = gate_radius
    else:  # the accumulator spans the surveillance region
        params["region"] = sc.region.as_tuple()
    ini = make_initiator(method, theta_deg=theta_deg, **params)
    res = run_initiation(sc, ini, fusion=fusion, runs=runs, seed=seed, weighting=weighting,
                         progress=show_progress())
    M = 3  # a track is true with ≥ 3 plots of one target; initiable: seen in ≥ 3 scans
    m = initiation_metrics(
        [track_targets(w.track_origins, M) for w in res.windows],
        [initiable_targets(w.target_ids, w.target_scans, M) for w in res.windows],
        n_runs=runs,
        window_seconds=[w.seconds for w in res.windows],
    )
    fs = res.fusion_seconds
    d = {"scenario": sc.name, "method": method, "fusion": fusion, "theta_deg": theta_deg,
         "runs": runs, "seed": seed, "clutter_rate": _rate(sc), **m.to_dict(),
         "t_fusion_scan": sum(fs) / len(fs) if fs else float("nan")}
    if figure is not None:
        from mhtrack.plotting.scene import save_figure
        from mhtrack.reports.initiation import initiation_figure_for

        save_figure(initiation_figure_for(sc, seed, fusion=fusion, theta_deg=theta_deg,
                                          gate_radius=gate_radius, v_min=v_min, v_max=v_max),
                    figure)
    if as_json:
        echo_json(d)
        return
    click.echo(
        f"{sc.name} ({method}, fusion {fusion}, θ = {theta_deg:g}°, λ = "
        f"{d['clutter_rate']:g} per radar, {runs} runs, {m.n_windows} windows)\n"
        f"  p_true           {m.p_true:.4f}\n"
        f"  p_false          {m.p_false:.4f}\n"
        f"  false tracks/run {m.false_per_run:.2f} ({m.false_per_window:.2f} per window)\n"
        f"  tracks/run       {m.tracks_per_run:.2f} (duplicates {m.duplicates_per_run:.2f})\n"
        f"  time/window      {1e3 * m.t_window:.2f} ms (fusion {1e3 * d['t_fusion_scan']:.2f}"
        f" ms/scan)"
    )


COMMANDS = [cluster, initiate]
