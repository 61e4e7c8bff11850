"""``track`` and ``run``: a tracker on a plots file, or simulate → track → evaluate → plot."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from mhtrack.cli.asterix_commands import needs_libasterix
from mhtrack.cli.clutter_options import clutter_estimator_options, clutter_params
from mhtrack.cli.common import (
    attributes_arg,
    attributes_options,
    clutter_frame_option,
    clutter_scene_option,
    echo_json,
    load_scenario_arg,
    scenario_options,
    with_scene_arg,
)
from mhtrack.cli.report_commands import page_options
from mhtrack.cli.terminal import say, show_progress
from mhtrack.names import (
    BIRTHS,
    DEFAULT_OUTPUT,
    DEFAULT_TRACKER,
    EVERY_PLOT,
    OUTPUTS,
    TRACKER_FUSIONS,
    TRACKERS,
)


def tracker_options(pd_flag: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """The tracker and its main parameters (defaults from P1 §3); ``pd_flag`` names the
    option of the tracker's detection probability."""
    return lambda f: _tracker_options(f, pd_flag)


def _tracker_options(f: Callable[..., Any], pd_flag: str) -> Callable[..., Any]:
    opts = [
        click.option("--tracker", type=click.Choice(sorted(TRACKERS)), default=DEFAULT_TRACKER,
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
        click.option("--birth", type=click.Choice(BIRTHS), default=EVERY_PLOT,
                     show_default=True, help="Which plots start new track trees: every plot "
                     "(P1), or tracks initiated by a P2 initiator over the last 4 scans (timed "
                     "plots: each radar's last 4 rotations)."),
        click.option("--birth-theta", "birth_theta", type=click.FloatRange(0, 180),
                     default=None, help="Angle limit θ (degrees) of the modified "
                     "initiators [20]."),
        click.option("--fusion", type=click.Choice(TRACKER_FUSIONS), default=None,
                     help="Fuse each scan's plots before tracking [adaptive-kmeans with "
                     "more than one sensor, else none]."),
    ]
    for opt in reversed(opts):
        f = opt(f)
    return f


def young_track_options(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--startup-density`` and ``--defer-tentative`` (``track``, ``run``, ``live``): how
    the MHT treats the targets a run starts on and its young trees (``docs/mht.md``;
    issue 30's dense scene)."""
    opts = [
        click.option("--startup-density", is_flag=True, help="Score the first scans' plots "
                     "with the density of targets not yet detected, estimated from the "
                     "first scan's plots in excess of the clutter, instead of λv "
                     "(MHTConfig.startup_density; --birth every-plot only)."),
        click.option("--defer-tentative", is_flag=True, help="N-scan pruning does not "
                     "commit a tentative tree to its chosen branch until the tree is "
                     "confirmed (MHTConfig.defer_tentative)."),
    ]
    for opt in reversed(opts):
        f = opt(f)
    return f


def young_track_fields(startup_density: bool, defer_tentative: bool,
                       birth: str | None) -> dict[str, Any]:
    """The :class:`~mhtrack.pipeline.TrackOptions` fields of :func:`young_track_options`
    (``None``: not given); ``--startup-density`` with another birth is a usage error."""
    if startup_density and birth not in (None, EVERY_PLOT):
        raise click.UsageError(f"--startup-density goes with --birth {EVERY_PLOT} "
                               f"(not {birth})")
    return {"startup_density": True if startup_density else None,
            "defer_tentative": True if defer_tentative else None}


_OUTPUT_HELP = (
    "history: each confirmed track also at the scans before its confirmation, back to its "
    "first plot (at most MHTConfig.history_scans back; from the seed scan with an "
    "initiator --birth), those rows marked tentative; online: only what the tracker "
    "reported at each scan; smoothed: the history with every track's positions and "
    "velocities smoothed over the whole track (fixed-interval Rauch-Tung-Striebel, "
    "IMM-aware), its rows not marked tentative the online rows, smoothed")


def bias_options(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--estimate-bias``, ``--bias-reference``, ``--bias-init``, ``--bias-out``
    (registration bias, ``docs/registration.md``): the same on ``track``, ``run`` and
    ``live``."""
    opts = [
        click.option("--estimate-bias", is_flag=True, help="Estimate each radar's "
                     "registration bias (range offset, range gain, azimuth offset) online "
                     "from aircraft that several sensors see, and correct its plots "
                     "(docs/registration.md)."),
        click.option("--bias-reference", type=int, default=None, metavar="ID",
                     help="With --estimate-bias: the radar whose bias is held at zero "
                     "[ADS-B if any, else the lowest radar id]."),
        click.option("--bias-init", type=click.Path(exists=True, dir_okay=False,
                     path_type=Path), default=None, help="With --estimate-bias: start from "
                     "the biases of an earlier run (a --bias-out file)."),
        click.option("--bias-out", type=click.Path(dir_okay=False, path_type=Path),
                     default=None, help="With --estimate-bias: write the final biases "
                     "(JSON) for --bias-init."),
    ]
    for opt in reversed(opts):
        f = opt(f)
    return f


def bias_fields(estimate_bias: bool, bias_reference: int | None, bias_init: Path | None,
                bias_out: Path | None) -> dict[str, Any]:
    """The :class:`~mhtrack.pipeline.TrackOptions` fields of :func:`bias_options` (the
    prior read from ``--bias-init``); the other options without ``--estimate-bias`` are
    a usage error."""
    if not estimate_bias and (bias_reference, bias_init, bias_out) != (None, None, None):
        raise click.UsageError("--bias-reference, --bias-init and --bias-out go with "
                               "--estimate-bias")
    prior = None
    if bias_init is not None:
        from mhtrack.io.biasfile import read_biases

        prior = read_biases(bias_init)
    return {"estimate_bias": estimate_bias, "bias_reference": bias_reference,
            "bias_prior": prior}


def report_biases(registration: Any, bias_out: Path | None, *, err: bool = False) -> None:
    """Print the estimated biases (:meth:`Registration.describe`) and write ``bias_out``."""
    if registration is None:
        return
    say("\n".join(registration.describe()), err=err)
    if bias_out is not None:
        from mhtrack.io.biasfile import write_biases

        write_biases(bias_out, registration.biases(), registration.references)
        say(f"biases -> {bias_out}", err=err)


def output_option(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--output history|online|smoothed``: which rows a batch run reports
    (``docs/mht.md``); default chosen by the pipeline (``pipeline.options.choose``)."""
    return click.option(
        "--output", "output", type=click.Choice(OUTPUTS), default=None,
        help=_OUTPUT_HELP + " [smoothed for timed plots or a recording of rotating radars "
        "(the defaults from the radars), else history].")(f)


def study_output_option(f: Callable[..., Any]) -> Callable[..., Any]:
    """``--output`` of a study of simulated scenarios (``montecarlo``): history unless
    given (a study's parameters name it)."""
    return click.option(
        "--output", "output", type=click.Choice(OUTPUTS), default=DEFAULT_OUTPUT,
        show_default=True, help=_OUTPUT_HELP + ".")(f)


def config_changes(tracker_pd: float | None, meas_sigma: float | None,
                   accel_sigma: float | None, birth_density: float | None,
                   nscan: int | None, imm_accel_sigma: float | None = None) -> dict[str, Any]:
    """The :class:`~mhtrack.mht.MHTConfig` fields that :func:`tracker_options` set (options
    left out are not changed), as :meth:`~mhtrack.pipeline.TrackOptions.config_changes`."""
    return track_options(DEFAULT_TRACKER, tracker_pd, meas_sigma, accel_sigma,
                         imm_accel_sigma, None, birth_density, nscan, None, None, None,
                         None).config_changes()


def track_options(tracker: str, tracker_pd: float | None, meas_sigma: float | None,
                  accel_sigma: float | None, imm_accel_sigma: float | None,
                  clutter_density: float | None, birth_density: float | None,
                  nscan: int | None, birth: str | None, birth_theta: float | None,
                  fusion: str | None, output: str | None, **more: Any) -> Any:
    """The :class:`~mhtrack.pipeline.TrackOptions` of :func:`tracker_options`,
    :func:`birth_options` and :func:`output_option` (``more``: other fields)."""
    from mhtrack.pipeline import TrackOptions

    return TrackOptions(
        tracker=tracker, p_detection=tracker_pd, sigma_w=meas_sigma, sigma_v=accel_sigma,
        imm_sigma_v=imm_accel_sigma, new_target_density=birth_density, n_scan=nscan,
        clutter_density=clutter_density, birth=birth, birth_theta_deg=birth_theta,
        fusion=fusion, output=output, **more)


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
@clutter_frame_option
@click.option("--sector-frames", is_flag=True, help="A recording: cut frames at each "
              "radar's own CAT034 sector crossings instead of eighths of its rotation "
              "(docs/real-radar.md: measured, and why it is not the default).")
@bias_options
@birth_options
@young_track_options
@output_option
@clutter_estimator_options
@needs_libasterix
def track(plots: Path, tracker: str, tracker_pd: float | None, meas_sigma: float | None,
          accel_sigma: float | None, imm_accel_sigma: float | None,
          clutter_density: float | None,
          birth_density: float | None, nscan: int | None, out: Path,
          scenario_file: Path | None, sensors_file: Path | None,
          reorder_window_s: float | None, clutter_frame: str, sector_frames: bool,
          birth: str,
          birth_theta: float | None, fusion: str | None, output: str | None,
          estimate_bias: bool = False, bias_reference: int | None = None,
          bias_init: Path | None = None, bias_out: Path | None = None,
          startup_density: bool = False, defer_tentative: bool = False,
          **estimator_opts: Any) -> None:
    """Run a tracker on a PLOTS file and write its tracks."""
    from mhtrack.io.paths import check_output_file
    from mhtrack.pipeline.run import Pipeline
    from mhtrack.sinks.files import TracksFileSink

    check_output_file(out, inputs=(plots, scenario_file, sensors_file), what="tracks file")
    options = track_options(tracker, tracker_pd, meas_sigma, accel_sigma, imm_accel_sigma,
                            clutter_density, birth_density, nscan, birth, birth_theta,
                            fusion, output, clutter_frame=clutter_frame,
                            **bias_fields(estimate_bias, bias_reference, bias_init, bias_out),
                            **young_track_fields(startup_density, defer_tentative, birth),
                            clutter_params=clutter_params(tracker, **estimator_opts))
    bars = show_progress()
    pipe = Pipeline.open(plots, options, scenario_file=scenario_file,
                         sensors_file=sensors_file, reorder_window_s=reorder_window_s,
                         progress=bars, sectors=sector_frames)
    result = pipe.run([TracksFileSink(out, frame=pipe.frame, output=pipe.output)],
                      progress=bars, keep_stats=False)
    say(f"{result.describe()} -> {out}")
    for note in (pipe.birth_note, pipe.reach_note, pipe.output_note):
        if note is not None:
            say(note)
    report_biases(pipe.registration, bias_out)


@click.command()
@scenario_options
@tracker_options("--tracker-pd")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Directory for plots, truth, tracks, metrics and figures "
              "[default: out/SCENARIO-TRACKER-SEED, out/SCENARIO-TRACKER-BIRTH-SEED with "
              "--birth other than every-plot].")
@click.option("--cutoff", type=click.FloatRange(min=0, min_open=True), default=None,
              help="OSPA/GOSPA cut-off c (m) [500].")
@click.option("--order", type=click.FloatRange(min=1), default=None,
              help="OSPA/GOSPA order p [2].")
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.option("--report", "html_report", is_flag=True,
              help="Also write report.html: one self-contained page (scene, metrics, "
              "parameters; needs mhtrack[report]); with the page options of `report` "
              "(--plotlyjs, --coastlines).")
@page_options
@birth_options
@young_track_options
@output_option
@clutter_scene_option
@click.option("--bias", "biases", multiple=True, metavar="ID:range=M,gain=G,azimuth=DEG",
              help="Give rotating radar ID a registration bias (as simulate --bias).")
@bias_options
@attributes_options
@clutter_estimator_options
def run(scenario: str, seed: int, clutter: str | None, clutter_rate: float | None,
        pd: float | None, scans: int | None, tracker: str, tracker_pd: float | None,
        meas_sigma: float | None, accel_sigma: float | None, imm_accel_sigma: float | None,
        clutter_density: float | None,
        birth_density: float | None, nscan: int | None, out: Path | None,
        cutoff: float | None, order: float | None, as_json: bool, html_report: bool,
        birth: str, birth_theta: float | None, fusion: str | None, output: str | None,
        clutter_scene: str | None = None, biases: tuple[str, ...] = (),
        estimate_bias: bool = False, bias_reference: int | None = None,
        bias_init: Path | None = None, bias_out: Path | None = None,
        attributes: bool | None = None, psr_only: float | None = None,
        ssr_only: float | None = None, garble: float | None = None,
        plotlyjs: str | None = None, coastlines: bool = False,
        startup_density: bool = False, defer_tentative: bool = False,
        **estimator_opts: Any) -> None:
    """Simulate SCENARIO, track, evaluate and plot, in one go.

    Writes plots, truth, tracks, scenario.toml, metrics.json, scene.png (truth, plots,
    tracks) and metrics.png (OSPA and cardinality per scan) to the output directory.
    """
    from mhtrack.experiments.pipeline import run_scenario
    from mhtrack.pipeline.options import warn_known_kappa
    from mhtrack.reports.run_files import run_dir, run_text, write_run

    if not html_report and (plotlyjs is not None or coastlines):
        raise click.UsageError("--plotlyjs and --coastlines are options of the page: "
                               "they need --report")
    if out is not None:
        from mhtrack.io.paths import check_output_dir

        check_output_dir(out, inputs=(Path(scenario) if Path(scenario).is_file() else None,),
                         what="run's files")
    sc = with_scene_arg(load_scenario_arg(scenario, clutter, clutter_rate, pd, scans),
                        clutter_scene)
    if biases:
        from mhtrack.scenario.biases import parse_bias, with_biases

        try:
            sc = with_biases(sc, [parse_bias(b) for b in biases])
        except ValueError as e:
            raise click.BadParameter(str(e), param_hint="--bias") from None
    options = track_options(tracker, tracker_pd, meas_sigma, accel_sigma, imm_accel_sigma,
                            clutter_density, birth_density, nscan, birth, birth_theta,
                            fusion, output, sensor_pd=pd,
                            **bias_fields(estimate_bias, bias_reference, bias_init, bias_out),
                            **young_track_fields(startup_density, defer_tentative, birth),
                            clutter_params=clutter_params(tracker, **estimator_opts))
    warn_known_kappa(sc, options)
    result = run_scenario(sc, seed, options=options, cutoff=cutoff, order=order,
                          progress=show_progress(),
                          attributes=attributes_arg(sc, attributes, psr_only, ssr_only,
                                                    garble))
    out = out if out is not None else run_dir(sc, tracker, birth, seed)
    summary = write_run(out, result, seed)
    page = None
    if html_report:
        from mhtrack.cli.report_commands import write_report_or_fail

        page = write_report_or_fail(out, plotlyjs=plotlyjs, coastlines=coastlines)
    if as_json:
        echo_json(summary)
        if page is not None:
            say(f"wrote {page}", err=True)
        report_biases(result.registration, bias_out, err=True)
        return
    for line in run_text(result, out):
        say(line)
    if page is not None:
        say(f"wrote {page}")
    report_biases(result.registration, bias_out)


COMMANDS = [track, run]
