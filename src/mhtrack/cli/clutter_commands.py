"""``clutter``: how well a clutter estimator recovers the simulated clutter intensity."""

from __future__ import annotations

from pathlib import Path

import click

from mhtrack.cli.common import echo_json, load_scenario_arg, scenario_options
from mhtrack.cli.terminal import say
from mhtrack.names import CLUTTER_ESTIMATORS


@click.command("clutter")
@scenario_options
@click.option("--estimator", type=click.Choice(CLUTTER_ESTIMATORS), default="agmm",
              show_default=True, help="Clutter estimator to score.")
@click.option("--clutter-density", type=click.FloatRange(min=0, min_open=True), default=None,
              help="κ (per m² per scan) of --estimator known [default: the scenario's true "
              "mean clutter count per scan spread uniformly over its region, S·λ̄/A].")
@click.option("--components", type=click.IntRange(min=1), default=None,
              help="K, Gaussian components to start from (gmm, agmm) [8].")
@click.option("--window", type=click.IntRange(min=1), default=None,
              help="W, scans pooled per fit (gmm, agmm) [5].")
@click.option("--oracle-gates", is_flag=True,
              help="Leave the true target plots out of the fit (source=outside-gates fed the "
              "true target mask) [default: the estimator sees every plot].")
@click.option("--resolution", type=click.IntRange(min=2, max=4000), default=400,
              show_default=True,
              help="Cells per side of the IAE quadrature grid.")
@click.option("--map-scan", type=int, default=None,
              help="Scan of the intensity maps figure [default: the middle scan].")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Directory for clutter.json and clutter.png "
              "[default: out/SCENARIO-clutter-ESTIMATOR-SEED].")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
def clutter(scenario: str, seed: int, clutter: str | None, clutter_rate: float | None,
            pd: float | None, scans: int | None, estimator: str,
            clutter_density: float | None, components: int | None, window: int | None,
            oracle_gates: bool, resolution: int, map_scan: int | None, out: Path | None,
            as_json: bool) -> None:
    """Simulate SCENARIO, run a clutter estimator on every scan and score it against the
    true intensity: IAE = ∫|κ̂ − κ| per scan and the count error |M̂ − λ| (mean over
    scans). Writes DIR/clutter.json (per-scan arrays) and DIR/clutter.png (true and
    estimated intensity maps at one scan) and, for the clutter map (--estimator map),
    DIR/clutter_maps.png (the map at four scans)."""
    from mhtrack.build import make_clutter_estimator
    from mhtrack.experiments.clutter_study import clutter_accuracy
    from mhtrack.io.atomic import atomic_write
    from mhtrack.io.jsonsafe import dumps
    from mhtrack.metrics.clutter import uniform_guess
    from mhtrack.plotting.clutter import plot_intensity_maps, save_maps
    from mhtrack.scenario import simulate

    sc = load_scenario_arg(scenario, clutter, clutter_rate, pd, scans)
    sim = simulate(sc, seed=seed)
    idx = sc.scan_indices()
    k_map = int(idx[len(idx) // 2]) if map_scan is None else map_scan
    if k_map not in set(idx.tolist()):
        raise click.BadParameter(f"scan {k_map} is not in {sc.first}..{sc.last}",
                                 param_hint="--map-scan")
    kappa = clutter_density if clutter_density is not None else uniform_guess(sim)
    est = make_clutter_estimator(estimator, kappa=kappa, n_components=components,
                                 window=window,
                                 source="outside-gates" if oracle_gates else None)
    quarters = [int(idx[min(len(idx) - 1, len(idx) * q // 4)]) for q in (1, 2, 3, 4)]
    acc = clutter_accuracy(est, sim, resolution=resolution, oracle_gates=oracle_gates,
                           map_scans=[k_map], snapshot_scans=quarters)
    summary = {"scenario": sc.name, "seed": seed, **acc.to_dict(), "map_scan": k_map}
    if estimator == "known":
        summary["clutter_density"] = kappa
    out = out if out is not None else Path("out") / f"{sc.name}-clutter-{estimator}-{seed}"
    out.mkdir(parents=True, exist_ok=True)
    atomic_write(out / "clutter.json", dumps(summary, indent=1))
    true, hat = acc.maps[k_map]
    z = sim.plots.z[sim.plots.scan == k_map]
    fig = plot_intensity_maps(
        true, hat, sc.region, plots=z, titles=(f"true κ, scan {k_map}", f"{estimator} κ̂"),
        title=f"{sc.name}, seed {seed}: IAE {acc.iae[list(acc.scans).index(k_map)]:.2f} "
        f"at this scan, mean {acc.iae_mean:.2f}",
    )
    save_maps(fig, out / "clutter.png")
    written = "clutter.json, clutter.png"
    if acc.snapshots:  # a clutter map: drawn per radar at four times
        from mhtrack.reports.clutter_maps import write_clutter_maps

        write_clutter_maps(out, acc.snapshots, title=f"{sc.name}, seed {seed}: clutter map")
        written += ", clutter_maps.png"
    if as_json:
        echo_json(summary)
        return
    say(f"{sc.name}, seed {seed}, {estimator}: iae_mean {acc.iae_mean:.3f}, "
        f"count_error_mean {acc.count_error_mean:.3f} "
        f"(true mean count {summary['rate_mean']:.2f}/scan), "
        f"{summary['ms_per_update']:.2f} ms/update")
    say(f"wrote {out}/ ({written})")


COMMANDS = [clutter]
