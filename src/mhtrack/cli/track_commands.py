"""``track`` and ``run``: a tracker on a plots file, or simulate → track → evaluate → plot."""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from mhtrack.cli.asterix_commands import recording_hook
from mhtrack.cli.common import echo_json, load_scenario_arg, scenario_options
from mhtrack.cli.terminal import progress_enabled, progress_option
from mhtrack.names import BIRTHS, CLUTTER_FRAMES, OUTPUTS, TRACKER_FUSIONS, TRACKERS


def tracker_options(pd_flag: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """The tracker and its main parameters (defaults from P1 §3); ``pd_flag`` names the
    option of the tracker's detection probability."""
    return lambda f: _tracker_options(f, pd_flag)


def _tracker_options(f: Callable[..., Any], pd_flag: str) -> Callable[..., Any]:
    opts = [
        click.option("--tracker", type=click.Choice(sorted(TRACKERS)), default="mht-agmm",
                     show_default=True, help="Tracker (and its clutter estimator)."),
        click.option(pd_flag, "tracker_pd", type=click.FloatRange(0, 1, min_open=True,
                     max_open=True), default=None,
                     help="Detection probability assumed by the tracker [0.9; with run, the "
                     "scenario's --pd when given]."),
        click.option("--meas-sigma", type=click.FloatRange(min=0, min_open=True), default=None,
                     help="Measurement noise σw (m) of Cartesian plots [100]."),
        click.option("--accel-sigma", type=click.FloatRange(min=0), default=None,
                     help="Process noise σv (m/s²) of the manoeuvre model [10]."),
        click.option("--imm-accel-sigma", type=click.FloatRange(min=0), default=None,
                     help="Process noise (m/s²) of the IMM's quiet model; 0 for P1's single "
                     "constant-velocity model [1]."),
        click.option("--clutter-density", type=click.FloatRange(min=0, min_open=True),
                     default=None, help="Known clutter intensity κ (per m² per scan) for "
                     "--tracker mht [1e-9]."),
        click.option("--birth-density", type=click.FloatRange(min=0, min_open=True),
                     default=None, help="New-target density λv, per m² per scan, used as "
                     "given (MHTConfig.new_target_density) [P1's 6.4 new targets per scan "
                     "over the surveillance area: the scenario's region, else the plots' "
                     "robust bounding box; 1e-7 on P1's 8 km × 8 km region]."),
        click.option("--nscan", type=click.IntRange(min=1), default=None,
                     help="N-scan pruning depth [3]."),
    ]
    for opt in reversed(opts):
        f = opt(f)
    return f


def birth_options(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--birth``, ``--birth-theta`` and ``--fusion`` (birth process and plot fusion of
    the MHT; ``docs/mht.md``)."""
    opts = [
        click.option("--birth", type=click.Choice(BIRTHS), default="every-plot",
                     show_default=True, help="Which plots start new track trees: every plot "
                     "(P1), or tracks initiated by a P2 initiator over the last 4 scans."),
        click.option("--birth-theta", "birth_theta", type=click.FloatRange(0, 180),
                     default=20.0, show_default=True,
                     help="Angle limit θ (degrees) of the modified initiators."),
        click.option("--fusion", type=click.Choice(TRACKER_FUSIONS), default=None,
                     help="Fuse each scan's plots before tracking [adaptive-kmeans with "
                     "more than one sensor, else none]."),
    ]
    for opt in reversed(opts):
        f = opt(f)
    return f


def output_option(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--output history|online``: which rows a batch run reports (``docs/mht.md``)."""
    return click.option(
        "--output", "output", type=click.Choice(OUTPUTS), default="history",
        show_default=True,
        help="history: each confirmed track also at the scans before its confirmation, back "
        "to its first plot (at most MHTConfig.history_scans back; from the seed scan with "
        "an initiator --birth), those rows marked tentative; online: only what the tracker "
        "reported at each scan.")(f)


def _check_clutter_density(tracker: str, clutter_density: float | None) -> None:
    from mhtrack.build import takes_clutter_density

    if clutter_density is not None and not takes_clutter_density(tracker):
        raise click.UsageError(
            f"--clutter-density sets the known clutter intensity of --tracker mht; "
            f"--tracker {tracker} estimates it online"
        )


def config_changes(tracker_pd: float | None, meas_sigma: float | None,
                   accel_sigma: float | None, birth_density: float | None,
                   nscan: int | None, imm_accel_sigma: float | None = None) -> dict[str, Any]:
    """The :class:`~mhtrack.mht.MHTConfig` fields that :func:`tracker_options` set (options
    left out are not changed)."""
    fields = {"p_detection": tracker_pd, "sigma_w": meas_sigma, "sigma_v": accel_sigma,
              "new_target_density": birth_density, "n_scan": nscan,
              "imm_sigma_v": imm_accel_sigma}
    return {k: v for k, v in fields.items() if v is not None}


def _config(base: Any, tracker_pd: float | None, meas_sigma: float | None,
            accel_sigma: float | None, birth_density: float | None, nscan: int | None,
            imm_accel_sigma: float | None) -> Any:
    from mhtrack.build import config_with

    return config_with(base, **config_changes(tracker_pd, meas_sigma, accel_sigma,
                                              birth_density, nscan, imm_accel_sigma))


@click.command()
@click.argument("plots", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@tracker_options("--pd")
@click.option("--out", type=click.Path(dir_okay=False, path_type=Path), required=True,
              help="Tracks file to write (.csv or .parquet).")
@click.option("--scenario", "scenario_file", type=click.Path(exists=True, dir_okay=False,
              path_type=Path), default=None,
              help="Scenario TOML giving the sensors (needed for polar plots) and all scan "
              "times [default: scenario.toml beside PLOTS, if any, without --sensors].")
@click.option("--sensors", "sensors_file", type=click.Path(exists=True, dir_okay=False,
              path_type=Path), default=None,
              help="Sensors file (TOML: radar sites, errors, P_D, periods) for timed plots "
              "(no scan column): converts range/bearing and lat/lon plots, and adds lat, "
              "lon and east/north vx, vy to the tracks (docs/file-formats.md) [default: "
              "sensors.toml beside timed PLOTS, if any].")
@click.option("--reorder-window", "reorder_window_s", type=click.FloatRange(min=0),
              default=None, help="Timed plots may be out of time order by at most this "
              "many seconds [2].")
@click.option("--clutter-frame", type=click.Choice(CLUTTER_FRAMES), default="polar",
              show_default=True, help="Timed plots: estimate each radar's clutter in the "
              "local east-north plane or in the radar's own range and bearing "
              "(docs/clutter.md).")
@birth_options
@output_option
@progress_option
def track(plots: Path, tracker: str, tracker_pd: float | None, meas_sigma: float | None,
          accel_sigma: float | None, imm_accel_sigma: float | None,
          clutter_density: float | None,
          birth_density: float | None, nscan: int | None, out: Path,
          scenario_file: Path | None, sensors_file: Path | None,
          reorder_window_s: float | None, clutter_frame: str, birth: str,
          birth_theta: float, fusion: str | None, output: str,
          progress: bool | None) -> None:
    """Run a tracker on a PLOTS file and write its tracks."""
    import numpy as np

    from mhtrack.build import default_config, default_fusion, make_tracker
    from mhtrack.experiments.pipeline import track as run_tracker
    from mhtrack.io import write_tracks
    from mhtrack.io.paths import check_output_file

    check_output_file(out, inputs=(plots, scenario_file, sensors_file), what="tracks file")
    plots, sensors_file = recording_hook(plots, sensors_file)  # ASTERIX: a plots file
    table, scenario, sensor_set = _read_input(plots, scenario_file, sensors_file,
                                              reorder_window_s)
    if fusion is None:  # frames of timed plots hold one sensor each: nothing to fuse
        n_sensors = (len(scenario.sensors) if scenario is not None
                     else len(np.unique(table.sensor)))
        fusion = "none" if table.timed else default_fusion(n_sensors)
    area = None
    if scenario is not None:
        base = default_config(scenario)
    else:  # no scenario: a robust box around the plots is the surveillance area
        area = _plots_area(plots, table) if len(table) > 1 else None
        base = default_config(area=area.area) if area is not None else default_config()
    cfg = _config(base, tracker_pd, meas_sigma, accel_sigma, birth_density, nscan,
                  imm_accel_sigma)
    _check_clutter_density(tracker, clutter_density)
    trk = make_tracker(tracker, cfg, clutter_density=clutter_density, birth=birth,
                       theta_deg=birth_theta, sensors=sensor_set, clutter_frame=clutter_frame)
    result = run_tracker(trk, table, name=tracker, progress=progress_enabled(progress),
                         fusion=fusion, output=output)
    frame = None
    if sensor_set is not None and sensor_set.reference is not None:
        frame = sensor_set.frame()
    write_tracks(result.tracks, out, frame, plots=table)
    n_ids = len(set(result.tracks.track_id.tolist()))
    caps = f", caps acted: {result.caps}" if result.caps else ""
    steps = "frames" if table.timed else "scans"
    click.echo(f"{tracker}: {len(result.stats)} {steps}, {n_ids} tracks, "
               f"{1e3 * result.t_avg:.2f} ms/scan{caps} -> {out}")
    if birth_density is None:
        where = ("the scenario's region" if scenario is not None
                 else f"the plots' {area.width / 1e3:.3g} km × {area.height / 1e3:.3g} km "
                 "bounding box" if area is not None
                 else "P1's 8 km × 8 km region")
        click.echo(birth_density_note(cfg.new_target_density, where))


def _read_input(plots: Path, scenario_file: Path | None, sensors_file: Path | None,
                reorder_window_s: float | None) -> tuple[Any, Any, Any]:
    """``(plots table, scenario or None, SensorSet or None)`` of the ``track`` command."""
    from mhtrack.io import read_plots
    from mhtrack.io.plots import check_scan_times, is_timed
    from mhtrack.io.sensors import read_sensors
    from mhtrack.io.timed_plots import DEFAULT_REORDER_WINDOW_S

    window = DEFAULT_REORDER_WINDOW_S if reorder_window_s is None else reorder_window_s
    timed = is_timed(plots)
    if timed:
        if scenario_file is not None:
            raise click.UsageError(f"{plots} holds timed plots (no scan column): give "
                                   "their sensors with --sensors FILE, not --scenario")
        if sensors_file is None and (plots.parent / "sensors.toml").is_file():
            sensors_file = plots.parent / "sensors.toml"
    elif scenario_file is not None and sensors_file is not None:
        raise click.UsageError("give --scenario (scans) or --sensors (timed plots), not both")
    if sensors_file is not None:
        sensor_set = read_sensors(sensors_file)
        return read_plots(plots, sensors=sensor_set, reorder_window_s=window), None, sensor_set
    if scenario_file is None and (plots.parent / "scenario.toml").is_file():
        scenario_file = plots.parent / "scenario.toml"
    sensors = None
    scenario = None
    if scenario_file is not None and not timed:
        from mhtrack.scenario import load_scenario

        scenario = load_scenario(scenario_file)
        sensors = {s.id: s for s in scenario.sensors}
    table = read_plots(plots, sensors=sensors, reorder_window_s=window)
    if scenario is not None:
        check_scan_times(plots, table, scenario.scan_indices(), scenario.scan_times(),
                         f"scenario {scenario_file}")
        table = dataclasses.replace(
            table, scan_times=(scenario.scan_indices(), scenario.scan_times())
        )
    elif table.range is not None:
        option = "--sensors with the radars" if table.timed else "--scenario with the radar(s)"
        logging.getLogger("mhtrack").warning(
            "%s has range/bearing columns (polar plots), but no %s gives its sensors: they "
            "are ignored and x, y tracked as Cartesian plots with the tracker's σw; pass %s "
            "to use the polar measurement model", plots,
            "sensors file" if table.timed else "scenario", option)
    return table, scenario, None


@click.command()
@scenario_options
@tracker_options("--tracker-pd")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Directory for plots, truth, tracks, metrics and figures "
              "[default: out/SCENARIO-TRACKER-SEED, out/SCENARIO-TRACKER-BIRTH-SEED with "
              "--birth other than every-plot].")
@click.option("--cutoff", type=click.FloatRange(min=0, min_open=True), default=500.0,
              show_default=True, help="OSPA/GOSPA cut-off c (m).")
@click.option("--order", type=click.FloatRange(min=1), default=2.0, show_default=True,
              help="OSPA/GOSPA order p.")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.option("--report", "html_report", is_flag=True,
              help="Also write report.html: one self-contained page (scene, metrics, "
              "parameters; needs mhtrack[report]).")
@birth_options
@output_option
@progress_option
def run(scenario: str, seed: int, clutter: str | None, clutter_rate: float | None,
        pd: float | None, scans: int | None, tracker: str, tracker_pd: float | None,
        meas_sigma: float | None, accel_sigma: float | None, imm_accel_sigma: float | None,
        clutter_density: float | None,
        birth_density: float | None, nscan: int | None, out: Path | None, cutoff: float,
        order: float, as_json: bool, html_report: bool, birth: str, birth_theta: float,
        fusion: str | None, output: str, progress: bool | None) -> None:
    """Simulate SCENARIO, track, evaluate and plot, in one go.

    Writes plots, truth, tracks, scenario.toml, metrics.json, scene.png (truth, plots,
    tracks) and metrics.png (OSPA and cardinality per scan) to the output directory.
    """
    from mhtrack.build import capped_pd, default_config
    from mhtrack.experiments.pipeline import run_scenario
    from mhtrack.io import write_plots, write_scenario_toml, write_tracks, write_truth
    from mhtrack.io.atomic import atomic_write
    from mhtrack.io.jsonsafe import dumps
    from mhtrack.plotting.metrics import plot_ospa_cardinality
    from mhtrack.plotting.scene import plot_scene, save_figure

    if out is not None:
        from mhtrack.io.paths import check_output_dir

        check_output_dir(out, inputs=(Path(scenario) if Path(scenario).is_file() else None,),
                         what="run's files")
    sc = load_scenario_arg(scenario, clutter, clutter_rate, pd, scans)
    if tracker_pd is None and pd is not None:  # the scenario's P_D, as default_config caps it
        tracker_pd = capped_pd(pd)
    cfg = _config(default_config(sc), tracker_pd, meas_sigma, accel_sigma, birth_density,
                  nscan, imm_accel_sigma)
    _check_clutter_density(tracker, clutter_density)
    _warn_known_kappa(sc, tracker, clutter_density)
    result = run_scenario(sc, seed, tracker, cfg, clutter_density=clutter_density,
                          cutoff=cutoff, order=order, progress=progress_enabled(progress),
                          birth=birth, theta_deg=birth_theta, fusion=fusion, output=output)
    suffix = "" if birth == "every-plot" else f"-{birth}"
    out = out if out is not None else Path("out") / f"{sc.name}-{tracker}{suffix}-{seed}"
    out.mkdir(parents=True, exist_ok=True)
    sim = result.simulation
    frame = _output_frame(sc, sim.plots)
    write_plots(sim.plots, out / "plots.csv")
    write_truth(sim.truth, out / "truth.csv", frame)
    write_tracks(result.run.tracks, out / "tracks.csv", frame, plots=sim.plots)
    write_scenario_toml({"seed": seed, **sc.to_dict()}, out / "scenario.toml")
    summary = result.summary()
    atomic_write(out / "metrics.json", dumps(summary, indent=1))
    title = f"{sc.name}, {tracker}, seed {seed}"
    save_figure(plot_scene(sim.plots, sim.truth, result.run.tracks, title=title),
                out / "scene.png")
    save_figure(plot_ospa_cardinality({tracker: summary}, cutoff=cutoff, title=title),
                out / "metrics.png")
    page = None
    if html_report:
        from mhtrack.cli.report_commands import write_report_or_fail

        page = write_report_or_fail(out)
    if as_json:
        echo_json(summary)
        if page is not None:
            click.echo(f"wrote {page}", err=True)
        return
    click.echo(result.evaluation.to_table())
    click.echo("output: " + ("history (each track also before its confirmation, rows "
                             "marked tentative)" if output == "history"
                             else "online (what the tracker reported at each scan)"))
    click.echo(f"tracker time: {1e3 * result.run.t_avg:.2f} ms/scan (mean)")
    if birth_density is None:
        click.echo(birth_density_note(cfg.new_target_density, "the scenario's region"))
    if result.run.caps:
        click.echo(f"hard caps acted: {result.run.caps}")
    click.echo(f"wrote {out}/ (plots, truth, tracks, metrics.json, scene.png, metrics.png)")
    if page is not None:
        click.echo(f"wrote {page}")


def birth_density_note(density: float, where: str) -> str:
    """The line saying which new-target density a run used when ``--birth-density`` was
    not given (:func:`~mhtrack.build.default_config`)."""
    from mhtrack.build import P1_BIRTHS_PER_SCAN

    return (f"new-target density λv = {density:.4g} per m² per scan: P1's "
            f"{P1_BIRTHS_PER_SCAN:g} new targets per scan over {where} (--birth-density "
            "sets it)")


def _output_frame(sc: Any, plots: Any) -> Any:
    """The local frame of a simulation's geodetic radars (timed plots), for the lat/lon
    columns of its truth and tracks files; ``None`` for synchronous scans."""
    if not plots.timed:
        return None
    sensor_set = sc.sensor_set()
    return sensor_set.frame() if sensor_set.reference is not None else None


def _plots_area(plots: Path, table: Any) -> Any:
    """Surveillance area of a plots file with no scenario, a
    :class:`~mhtrack.build.PlotsArea` (:func:`~mhtrack.build.plots_area`); warns about
    plots far outside its box."""
    from mhtrack.build import plots_area

    box = plots_area(table.x, table.y)
    if box.n_far:
        logging.getLogger("mhtrack").warning(
            "%s: %d of %d plots lie far outside the box holding the middle 99%% of the plots "
            "(x %.6g to %.6g m, y %.6g to %.6g m); the surveillance area (%.4g m²) is taken "
            "from that box — check those plots, or pass --scenario with the true region",
            plots, box.n_far, len(table), box.x0, box.x1, box.y0, box.y1, box.area)
    return box


def _warn_known_kappa(sc: Any, tracker: str, clutter_density: float | None) -> None:
    """Warn when a known-clutter tracker keeps P1's κ on a scenario whose clutter is 10×
    denser or sparser (:func:`~mhtrack.build.known_kappa_mismatch`)."""
    from mhtrack.build import DEFAULT_CLUTTER_DENSITY, known_kappa_mismatch, takes_clutter_density

    if not takes_clutter_density(tracker) or clutter_density is not None:
        return
    mean = known_kappa_mismatch(sc)
    if mean is not None:
        logging.getLogger("mhtrack").warning(
            "tracker mht assumes P1's clutter density %.3g per m²; this scenario's clutter "
            "averages %.3g per m² over its region: pass --clutter-density %.3g, or use "
            "mht-agmm, which estimates it", DEFAULT_CLUTTER_DENSITY, mean, mean)


COMMANDS = [track, run]
