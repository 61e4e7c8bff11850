"""``simulate``, ``evaluate`` and ``plot``: scenarios, files and metrics."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from mhtrack.cli.common import (
    InputProblem,
    attributes_arg,
    attributes_options,
    clutter_scene_option,
    echo_json,
    load_scenario_arg,
    scenario_options,
    table_path,
    with_scene_arg,
)
from mhtrack.cli.terminal import say, show_progress


@click.command()
@scenario_options
@click.option("--out", "out", type=click.Path(file_okay=False, path_type=Path), required=True,
              help="Output directory (created).")
@click.option("--format", "fmt", type=click.Choice(["csv", "parquet"]), default="csv",
              show_default=True, help="File format of plots and truth.")
@click.option("--bias", "biases", multiple=True, metavar="ID:range=M,gain=G,azimuth=DEG",
              help="Give rotating radar ID a registration bias (range offset m, range "
                   "gain, azimuth offset degrees; repeat per radar). Written to "
                   "DIR/scenario.toml, not to the sensors file.")
@attributes_options
@clutter_scene_option
def simulate(scenario: str, seed: int, clutter: str | None, clutter_rate: float | None,
             pd: float | None, scans: int | None, out: Path, fmt: str, attributes: bool | None,
             psr_only: float | None, ssr_only: float | None, garble: float | None,
             biases: tuple[str, ...] = (), clutter_scene: str | None = None) -> None:
    """Simulate SCENARIO (a preset or a TOML file) and write DIR/plots, DIR/truth and the
    full parameters in DIR/scenario.toml.

    With rotating radars (e.g. opensky-radars): DIR/plots (time, sensor, range, bearing,
    origin; no scan), DIR/truth (scan = sample, time, target_id, x, y, lat, lon, vx, vy
    east/north m/s) and DIR/sensors.toml for `mhtrack track --sensors`."""
    from mhtrack.io import write_plots, write_scenario_toml, write_truth
    from mhtrack.io.paths import check_output_dir
    from mhtrack.scenario import simulate as run_simulation

    scenario_path = Path(scenario) if Path(scenario).is_file() else None
    check_output_dir(out, inputs=(scenario_path,), what="simulation files")
    sc = load_scenario_arg(scenario, clutter, clutter_rate, pd, scans)
    sc = with_scene_arg(sc, clutter_scene)
    if biases:
        from mhtrack.scenario.biases import parse_bias, with_biases

        try:
            sc = with_biases(sc, [parse_bias(b) for b in biases])
        except ValueError as e:
            raise click.BadParameter(str(e), param_hint="--bias") from None
    ssr = attributes_arg(sc, attributes, psr_only, ssr_only, garble)
    sim = run_simulation(sc, seed=seed)
    if ssr is not None:
        from mhtrack.scenario.identity import with_attributes

        sim = with_attributes(sim, ssr)
    out.mkdir(parents=True, exist_ok=True)
    if sc.rotating:
        _write_rotating(sim, out, fmt)
        return
    write_plots(sim.plots, out / f"plots.{fmt}")
    write_truth(sim.truth, out / f"truth.{fmt}")
    write_scenario_toml({"seed": seed, **sc.to_dict()}, out / "scenario.toml")
    n_scans = sim.plots.n_scans
    n_clutter = int((sim.plots.origin < 0).sum()) if sim.plots.origin is not None else 0
    say(
        f"{sc.name}: {n_scans} scans, {len(sim.plots)} plots ({n_clutter} clutter"
        f"{_ssr_note(sim.plots)}), "
        f"{len(set(sim.truth.target_id.tolist()))} targets -> {out}"
    )


def _ssr_note(plots: Any) -> str:
    """``"; SSR attributes"`` when the plots carry them (``simulate --help``), else ``""``."""
    return "; SSR attributes" if plots.attrs is not None else ""


def _write_rotating(sim: Any, out: Path, fmt: str) -> None:
    """The files of a rotating-radar simulation (``mhtrack simulate --help``): timed plots
    (no scan), truth with lat/lon and east/north velocities, the sensors file."""
    from mhtrack.io import write_plots, write_scenario_toml, write_truth
    from mhtrack.io.sensors import write_sensors

    sc, plots, truth = sim.scenario, sim.plots, sim.truth
    sensor_set = sc.sensor_set()
    write_plots(plots, out / f"plots.{fmt}")
    write_truth(truth, out / f"truth.{fmt}", sensor_set.frame())
    write_sensors(sensor_set, out / "sensors.toml")
    write_scenario_toml({"seed": sim.seed, **sc.to_dict()}, out / "scenario.toml")
    n_clutter = int((plots.origin < 0).sum())
    t0, t1 = sc.first * sc.T, sc.last * sc.T
    say(
        f"{sc.name}: {len(sc.sensors)} rotating radars over {t1 - t0:g} s, {len(plots)} "
        f"plots ({n_clutter} clutter{_ssr_note(plots)}), "
        f"{len(set(truth.target_id.tolist()))} targets -> {out}"
    )


@click.command()
@click.argument("tracks", type=click.Path(dir_okay=False, path_type=Path))
@click.argument("truth", type=click.Path(dir_okay=False, path_type=Path), required=False)
@click.option("--reference", "reference", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Score TRACKS against a reference system's tracks, an "
              "ASTERIX CAT062 recording (without CAT062: its CAT021 ADS-B reports), "
              "instead of TRUTH (docs/metrics.md).")
@click.option("--reference-period", "reference_period", type=click.FloatRange(
              min=0, min_open=True), default=None, help="With --reference: the times the "
              "reference is sampled at, every S seconds [default: its own median update "
              "interval].")
@click.option("--plots", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Plots file (adds the scans it covers and plot-based metrics).")
@click.option("--cutoff", type=click.FloatRange(min=0, min_open=True), default=500.0,
              show_default=True, help="OSPA/GOSPA cut-off c (m).")
@click.option("--order", type=click.FloatRange(min=1), default=2.0, show_default=True,
              help="OSPA/GOSPA order p.")
@click.option("--match-distance", type=click.FloatRange(min=0, min_open=True), default=None,
              help="Track-to-truth matching distance for CLEAR-MOT (m) [default: cut-off].")
@click.option("--sensors", "sensors_file", type=click.Path(exists=True, dir_okay=False,
              path_type=Path), default=None,
              help="Sensors file of timed (asynchronous) data: reads timed PLOTS and files "
              "that give positions only as lat/lon [default: sensors.toml beside TRUTH, if "
              "any].")
@click.option("--at", "at", type=click.Choice(["scans", "truth-times"]), default=None,
              help="Score at the tracks' scans, or at the truth's times with each track's "
              "latest state predicted to them [default: truth-times for tracks numbered by "
              "frame (timed plots), else scans; docs/metrics.md].")
@click.option("--max-age", "max_age_s", type=click.FloatRange(min=0), default=None,
              help="At truth times: the oldest track state (s) still predicted; with "
              "--reference: the longest gap between a track's updates interpolated "
              "across [15].")
@click.option("--identity", is_flag=True, help="Add the identity figures: ids per "
              "aircraft, wrong code/address rate (--plots with attributes and origins), "
              "horizontal RMS error, probability of update, extra and dubious track rates "
              "(docs/metrics.md).")
@click.option("--update-interval", "update_interval", type=click.FloatRange(
              min=0, min_open=True), default=None, help="With --identity: the probability "
              "of update's interval (s) [default: the truth's median time step].")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.option("--out", "-o", "out", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Write the table (.txt) or the JSON (.json) to FILE "
              "instead of stdout.")
def evaluate(tracks: Path, truth: Path | None, reference: Path | None,
             reference_period: float | None, plots: Path | None, cutoff: float,
             order: float, match_distance: float | None, sensors_file: Path | None,
             at: str | None, max_age_s: float | None, identity: bool,
             update_interval: float | None, as_json: bool, out: Path | None) -> None:
    """Score TRACKS against TRUTH (or a reference system's CAT062 tracks, --reference
    REC): OSPA, GOSPA, cardinality, CLEAR-MOT, coverage."""
    import logging

    from mhtrack.io import read_plots, read_tracks, read_truth
    from mhtrack.io.paths import check_output_file
    from mhtrack.io.sensors import read_sensors
    from mhtrack.io.tracks import has_frames
    from mhtrack.metrics import evaluate as run_evaluation
    from mhtrack.metrics.resample import DEFAULT_MAX_AGE_S, alignment
    from mhtrack.progress import Stages

    if (truth is None) == (reference is None):
        raise click.UsageError("give TRUTH or --reference REC (one of them)")
    if reference_period is not None and reference is None:
        raise click.UsageError("--reference-period applies to --reference only")
    if update_interval is not None and not identity:
        raise click.UsageError("--update-interval applies to --identity only")
    if reference is not None and identity:
        raise click.UsageError("--identity applies to TRUTH only")
    if reference is not None and (plots is not None or at is not None):
        raise click.UsageError("--plots and --at apply to TRUTH only (--reference scores "
                               "at the reference's own times)")
    if out is not None:
        check_output_file(out, inputs=(tracks, truth or reference, plots),
                          suffixes=(".json", ".txt"), what="metrics", option="--out")
    age = DEFAULT_MAX_AGE_S if max_age_s is None else max_age_s
    if reference is not None:
        ev = _against_reference(tracks, reference, reference_period, sensors_file,
                                cutoff, order, match_distance, age)
        _print(ev, as_json, out)
        return
    assert truth is not None
    if sensors_file is None and (truth.parent / "sensors.toml").is_file():
        sensors_file = truth.parent / "sensors.toml"
    sensor_set = read_sensors(sensors_file) if sensors_file is not None else None
    frame = sensor_set.frame() if sensor_set is not None else None
    run = Stages(3 + 8, "evaluate", show_progress())  # 3 files, 8 metrics
    try:
        pl = run("read plots", read_plots, plots, sensors=sensor_set) if plots else None
        tr = run("read tracks", read_tracks, tracks, frame=frame, plots=pl)
        gt = run("read truth", read_truth, truth, frame=frame)
        if at is None and not has_frames(tracks):
            at = "scans"  # tracks numbered by scan are scored at their scans, times checked
        if alignment(tr, gt, pl, at) == "scans":
            _check_same_times(tracks, tr, truth, gt)
            if pl is not None and plots is not None:
                _check_same_times(plots, pl, truth, gt)
        ev = run_evaluation(tr, gt, plots=pl, cutoff=cutoff, order=order,
                            match_distance=match_distance, at=at, stages=run,
                            max_age_s=age, identity=identity,
                            update_interval=update_interval)
    finally:
        run.close()
    logging.getLogger("mhtrack.metrics").info(
        "evaluated %s against %s: %d scans, %d tracks, %d targets", tracks, truth,
        len(ev.scans), ev.n_tracks, ev.n_targets)
    _print(ev, as_json, out)


def _against_reference(tracks: Path, rec: Path, period: float | None,
                       sensors_file: Path | None, cutoff: float, order: float,
                       match_distance: float | None, max_age_s: float) -> Any:
    """``evaluate TRACKS --reference REC``: the reference's CAT062 tracks as the truth
    (:func:`mhtrack.io.reference.read_reference`, its skipped records warned, one line
    per kind), our tracks placed in the same frame from their ``lat, lon``, both sampled
    at the reference's times (:func:`mhtrack.metrics.reference.evaluate_reference`)."""
    import numpy as np

    from mhtrack.io import InputError, read_tracks
    from mhtrack.io._frame import column_names
    from mhtrack.io.reference import read_reference
    from mhtrack.io.sensors import read_sensors
    from mhtrack.metrics.reference import evaluate_reference
    from mhtrack.progress import Stages

    for beside in (tracks.parent, rec.parent):
        if sensors_file is None and (beside / "sensors.toml").is_file():
            sensors_file = beside / "sensors.toml"
    sensor_set = read_sensors(sensors_file) if sensors_file is not None else None
    frame = sensor_set.frame() if sensor_set is not None and \
        sensor_set.reference is not None else None
    geodetic = {"lat", "lon"} <= set(column_names(tracks))
    if frame is None and not geodetic:
        raise click.UsageError(f"{tracks} has no lat, lon: give the sensors file of its "
                               "local frame (--sensors FILE) to place the reference in it")
    run = Stages(2 + 8, "evaluate", show_progress())  # 2 files, 8 metrics
    try:
        ref = run("read reference", read_reference, rec, frame)
        ref.problems.warn(str(rec))
        tr = run("read tracks", read_tracks, tracks, frame=ref.frame, geodetic=geodetic,
                 accept_truth=False)
        if len(tr):
            ref = ref.near(float(tr.time.min()))
        try:
            ev, truth, used = evaluate_reference(
                tr, ref.time, ref.key, ref.state, max_gap_s=max_age_s, period_s=period,
                cutoff=cutoff, order=order, match_distance=match_distance, stages=run)
        except ValueError as e:  # a reference that cannot be sampled: name the file
            hint = " (--reference-period S)" if "period" in str(e) else ""
            raise InputError(f"{rec}: {e}{hint}", file=str(rec)) from None
    finally:
        run.close()
    moved = f", moved by {ref.days:+d} day(s)" if ref.days else ""
    say(f"{rec}: {len(ref)} CAT062 updates of {len(np.unique(truth.target_id))} "
        f"reference tracks, sampled every {used:g} s at {len(np.unique(truth.scan))}"
        f" times{moved}", err=True)
    return ev


def _print(ev: Any, as_json: bool, out: Path | None) -> None:
    """The evaluation as a table or JSON, on stdout or written atomically to ``out``."""
    from mhtrack.io.atomic import atomic_write
    from mhtrack.io.jsonsafe import dumps

    if out is not None:
        text = (dumps(ev.to_dict()) if as_json else ev.to_table()) + "\n"
        say(f"wrote {atomic_write(out, text)}")
    elif as_json:
        echo_json(ev.to_dict())
    else:
        click.echo(ev.to_table())


def _check_same_times(path_a: Path, a: Any, path_b: Path, b: Any) -> None:
    """Two tables of one run give every scan they share the same time; else an
    :class:`~mhtrack.io.InputError` names both files and the first scan that differs."""
    from mhtrack.io import InputError
    from mhtrack.metrics._common import first_time_mismatch

    bad = first_time_mismatch(a.scan, a.time, b.scan, b.time)
    if bad is not None:
        k, ta, tb = bad
        raise InputError(
            f"{path_a} and {path_b} give scan {k} different times ({ta!r} s and {tb!r} s); "
            "they do not come from the same scans (same scan numbers must have the same time)",
            file=str(path_a),
        )


@click.command()
@click.argument("directory", type=click.Path(exists=True, file_okay=False, path_type=Path))
@click.option("--out", "-o", "output", type=click.Path(dir_okay=False, path_type=Path),
              default=None, help="Image file [default: DIR/scene.png].")
@click.option("--output", "output_alias", type=click.Path(dir_okay=False, path_type=Path),
              default=None, hidden=True)  # the former spelling, kept for a release
@click.option("--title", default=None, help="Figure title [default: the directory name].")
def plot(directory: Path, output: Path | None, output_alias: Path | None,
         title: str | None) -> None:
    """Draw DIR's truth, plots (clutter grey) and tracks, whichever are present."""
    from mhtrack.io import read_plots, read_toml, read_tracks, read_truth
    from mhtrack.io.paths import check_output_file
    from mhtrack.io.sensors import read_sensors
    from mhtrack.plotting.scene import plot_scene, save_figure, sensor_sites

    paths = {s: table_path(directory, s) for s in ("plots", "truth", "tracks")}
    output = output if output is not None else output_alias
    if output is not None:
        check_output_file(output, inputs=paths.values(), suffixes=(".png",), what="figure",
                          option="--out")
    if not any(paths.values()):
        raise InputProblem(f"{directory} holds no plots, truth or tracks file")
    if title is None:
        title = directory.name
        if (directory / "scenario.toml").is_file():
            title = str(read_toml(directory / "scenario.toml").get("name", title))
    sensors = directory / "sensors.toml"  # radars at geodetic sites: drawn, and their frame
    sensor_set = read_sensors(sensors) if sensors.is_file() else None
    frame = sensor_set.frame() if sensor_set is not None else None
    plots = read_plots(paths["plots"], sensors=sensor_set) if paths["plots"] else None
    fig = plot_scene(
        plots=plots,
        truth=read_truth(paths["truth"], frame=frame) if paths["truth"] else None,
        tracks=read_tracks(paths["tracks"], frame=frame, plots=plots)
        if paths["tracks"] else None,
        title=title,
        sites=sensor_sites(sensor_set) if sensor_set is not None else None,
    )
    path = save_figure(fig, output or directory / "scene.png")
    say(f"wrote {path}")


COMMANDS = [simulate, evaluate, plot]
