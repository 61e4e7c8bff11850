"""``mhtrack report DIR``: one self-contained HTML page of a run or of a study.

* **A run** (``run``'s output, or a directory of ``simulate`` + ``track`` files): the
  scene (truth, plots, tracks, radar sites; the lat/lon grid when a sensors file or the
  scenario gives a geodetic origin), OSPA, OSPA(2) when evaluated, and cardinality per
  scan, the metrics table, the scenario's and the evaluation's parameters and the hard
  caps of the MHT that acted. Metrics are read from ``metrics.json`` (``run``, or
  ``evaluate --json > DIR/metrics.json``); without it, and with truth and tracks present,
  they are computed here with ``evaluate``'s defaults, and the page says so.
* **A study** (a ``montecarlo`` directory, ``montecarlo.json``): OSPA, OSPA(2) and
  cardinality per scan (mean ± std per tracker), mean ± std per tracker and metric, the
  paired comparisons with their 95 % intervals when available
  (:mod:`~mhtrack.reports.html_study`), the study's parameters and caps.

Pages are built by :class:`~mhtrack.reports.html_page.Page` with Plotly (the optional
extra ``mhtrack[report]``).
"""

from __future__ import annotations

import json
import logging
from pathlib import Path
from typing import Any

import numpy as np

from mhtrack.io.atomic import atomic_write
from mhtrack.progress import Stages, silent
from mhtrack.reports.html_metrics import curves_figure, fmt, metric_rows
from mhtrack.reports.html_page import Page, require_plotly

log = logging.getLogger("mhtrack.reports")
REPORT_FILE = "report.html"
#: ``montecarlo``'s spec file: its presence makes a directory a study.
STUDY_FILE = "montecarlo.json"


def _table(directory: Path, stem: str) -> Path | None:
    for ext in (".csv", ".parquet"):
        if (p := directory / f"{stem}{ext}").is_file():
            return p
    return None


def _geometry(directory: Path) -> tuple[Any, Any, list[Any], Any]:
    """``(scenario or None, SensorSet or None, radar sites, LocalFrame or None)`` from
    ``sensors.toml`` or ``scenario.toml`` in ``directory``."""
    from mhtrack.io.sensors import read_sensors
    from mhtrack.plotting.scene import sensor_sites
    from mhtrack.scenario import load_scenario

    scenario = None
    if (directory / "scenario.toml").is_file():
        scenario = load_scenario(directory / "scenario.toml")
    sensor_set = None
    if (directory / "sensors.toml").is_file():
        sensor_set = read_sensors(directory / "sensors.toml")
    elif scenario is not None and (scenario.origin is not None or any(
            getattr(s, "lat", None) is not None for s in scenario.sensors)):
        sensor_set = scenario.sensor_set()
    if sensor_set is not None:
        frame = sensor_set.frame() if sensor_set.reference is not None else None
        return scenario, sensor_set, sensor_sites(sensor_set), frame
    sites = [] if scenario is None else [
        (*s.position, f"radar {s.id}") for s in scenario.sensors
        if getattr(s, "position", None) is not None]
    return scenario, None, sites, None


def _evaluation(directory: Path, plots: Any, truth: Any, tracks: Any, run: Stages
                ) -> tuple[dict[str, Any] | None, str]:
    """``metrics.json`` if present, else an evaluation with ``evaluate``'s defaults when
    truth and tracks are there; and a note saying which."""
    path = directory / "metrics.json"
    if path.is_file():
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except ValueError as e:
            raise ValueError(f"{path}: not valid JSON ({e})") from None
        if not isinstance(data, dict):
            raise ValueError(f"{path}: expected one JSON object (evaluate --json)")
        return data, f"Metrics read from {path.name}."
    if truth is None or tracks is None:
        return None, ("No metrics: the directory has no metrics.json, and no truth file to "
                      "evaluate the tracks against." if truth is None else
                      "No metrics: the directory has no metrics.json and no tracks file.")
    from mhtrack.io.tracks import has_frames
    from mhtrack.metrics import evaluate

    tracks_path = _table(directory, "tracks")
    at = None if tracks_path is not None and has_frames(tracks_path) else "scans"
    ev = run("evaluate", evaluate, tracks, truth, plots=plots, at=at)
    return ev.to_dict(), ("No metrics.json: metrics computed for this page with evaluate's "
                          "defaults (c = 500 m, p = 2).")


def _run_parameters(scenario: Any, summary: dict[str, Any] | None, seed: Any
                    ) -> list[tuple[str, str]]:
    rows: list[tuple[str, str]] = []
    if scenario is not None:
        rows += [("scenario", scenario.name), ("description", scenario.description or "–")]
        if seed is not None:
            rows.append(("seed", str(seed)))
        rows += [("scans", f"{scenario.first}–{scenario.last} (T = {scenario.T:g} s)"),
                 ("sensors", ", ".join(f"{s.id}: {s.kind}" for s in scenario.sensors)),
                 ("clutter", _clutter_text(scenario))]
        r = scenario.region
        rows.append(("region", f"x {r.xmin:g} to {r.xmax:g} m, y {r.ymin:g} to {r.ymax:g} m"))
        if scenario.origin is not None:
            rows.append(("origin (lat, lon)", f"{scenario.origin[0]:g}, {scenario.origin[1]:g}"))
    if summary is not None:
        for key, label in (("tracker", "tracker"), ("output", "output"),
                           ("cutoff", "OSPA/GOSPA cut-off c (m)"), ("order", "order p"),
                           ("match_distance", "CLEAR-MOT matching distance (m)"),
                           ("ospa2_window", "OSPA(2) window (scans)"), ("at", "aligned at"),
                           ("max_age_s", "largest track-state age (s)"),
                           ("n_scans", "scans evaluated")):
            if summary.get(key) is not None:
                rows.append((label, fmt(summary[key])))
    return rows


def _clutter_text(scenario: Any) -> str:
    c = scenario.to_dict().get("clutter") or {}
    rate = c.get("rate")
    return str(c.get("kind", "none")) + (f", λ = {rate:g} per scan"
                                         if isinstance(rate, int | float) and rate > 0
                                         else "")


def _caps_text(caps: Any) -> list[tuple[str, str]]:
    if not caps:
        return [("hard caps of the MHT", "none acted")]
    if isinstance(caps, str):
        caps = json.loads(caps or "{}")
    return [(f"cap {k}", f"acted in {fmt(v)} scans") for k, v in dict(caps).items()]


def _title(directory: Path, scenario: Any, tracker: Any, seed: Any, plots: Any,
           tracks: Any, truth: Any) -> str:
    """The page's title: scenario (or folder) name, tracker, seed; for a recording without
    truth also its tracks, plots and radars."""
    name = scenario.name if scenario is not None else (directory.resolve().name or "run")
    parts = [name, tracker, None if seed is None else f"seed {seed}"]
    if truth is None:
        parts.append(None if tracks is None
                     else f"{len(np.unique(tracks.online().track_id))} tracks")
        if plots is not None:
            n_radars = len(np.unique(plots.sensor))
            parts.append(f"{len(plots)} plots from {n_radars} "
                         f"radar{'s' if n_radars != 1 else ''}")
    return ", ".join(str(v) for v in parts if v is not None)


def _recording_sections(page: Page, plots: Any, tracks: Any, details: dict[str, Any],
                        sensor_set: Any) -> None:
    """Radars, tracks and the histogram of track lengths (:mod:`html_recording`)."""
    from mhtrack.reports import html_recording as rec

    if plots is not None and len(plots):
        page.section("Radars")
        page.note("Per sensor: its plots, how many the tracks used, and the median time "
                  "between consecutive plots of one track from that sensor (its update "
                  "interval as the tracks saw it), beside the sensors file's period.")
        page.table(rec.RADAR_HEADER, rec.radar_rows(plots, tracks, rec.periods_of(sensor_set)))
    if tracks is not None:
        page.section("Tracks")
        page.note("Durations from the first to the last row of each track reported at its "
                  "own scan (rows written after confirmation not counted).")
        page.table(["", "value"], rec.track_rows(tracks, details))
        if len(tracks):
            page.figure(rec.lengths_figure(tracks), "lengths")


#: Stages of a run's page (the progress bar's length).
RUN_STAGES = 7


def run_page(directory: Path, stages: Stages | None = None, *, coastlines: bool = False
             ) -> Page:
    """The page of a run directory (module docstring); ``stages`` shows its progress;
    ``coastlines``: Natural Earth's coastlines and borders in a geographic scene,
    downloaded once into the cache if missing, off (the page says why) where
    unavailable (:mod:`mhtrack.io.basemap`)."""
    from mhtrack.io import read_plots, read_toml, read_tracks, read_truth
    from mhtrack.reports.html_recording import sensor_rows, track_details
    from mhtrack.reports.html_scene import MAX_PLOTS, MAX_TRACK_POINTS, scene_figure

    paths = {s: _table(directory, s) for s in ("plots", "truth", "tracks")}
    if not any(paths.values()):
        raise ValueError(f"{directory} holds no plots, truth or tracks file (nor "
                         f"{STUDY_FILE}): nothing to report")
    run = stages or silent()
    scenario, sensor_set, sites, frame = _geometry(directory)
    plots = (run("read plots", read_plots, paths["plots"], sensors=sensor_set)
             if paths["plots"] else None)
    lframe = sensor_set.frame() if sensor_set is not None and frame is not None else None
    truth = run("read truth", read_truth, paths["truth"], frame=lframe) if paths["truth"] \
        else None
    tracks = (run("read tracks", read_tracks, paths["tracks"], frame=lframe,
                  plots=plots if plots is not None and plots.timed else None)
              if paths["tracks"] else None)
    details = ({} if tracks is None else run("track details", track_details, tracks,
                                              paths["tracks"], plots, paths["plots"]))
    summary, source = _evaluation(directory, plots, truth, tracks, run)
    seed = (read_toml(directory / "scenario.toml").get("seed")
            if (directory / "scenario.toml").is_file() else None)
    tracker = (summary or {}).get("tracker")
    title = _title(directory, scenario, tracker, seed, plots, tracks, truth)
    page = Page(f"mhtrack report: {title}", str(directory))
    page.section("Scene")
    page.note(("Truth (black, o at birth, x at death), plots" if truth is not None
               else "Plots") + " (clutter grey), tracks (one colour per id, dotted before "
              "confirmation)" + (", radar sites (red)" if sites else "")
              + ". Hover a track for its speed, heading and what the files give (flight "
              "level, code, score, sensors). Drag to pan, wheel or box to zoom, "
              "double-click to reset, click a legend entry to hide it."
              + (" Dashed lines: latitude and longitude (WGS-84)"
                 + ("" if coastlines else ", no map") + "." if frame else ""))
    n_track_rows = 0 if tracks is None else len(tracks)
    if (plots is not None and len(plots) > MAX_PLOTS) or n_track_rows > MAX_TRACK_POINTS:
        page.note(f"Thinned for drawing: at most {MAX_PLOTS} plots of each kind and about "
                  f"{MAX_TRACK_POINTS} track rows are drawn (every k-th, evenly spread; the "
                  "legend says how many); the tables count every row.")
    layers = None
    if coastlines:
        from mhtrack.io.basemap import basemap

        layers, where = basemap(fetch=True) if frame is not None else ({}, (
            "Coastlines off: the scene has no geodetic origin (a sensors file or "
            "scenario with one)."))
        page.note(where)
    page.figure(run("scene", scene_figure, plots, truth, tracks, sites=sites, frame=frame,
                    title=title, details=details, basemap=layers), "scene")
    if truth is not None or summary is not None:
        page.section("Metrics over time")
        page.note(source)
        if summary is not None and summary.get("scans"):
            at_truth = summary.get("at") == "truth-times"
            page.figure(curves_figure({str(tracker or "tracks"): summary},
                                      cutoff=summary.get("cutoff"),
                                      ospa2_window=summary.get("ospa2_window"),
                                      x_title="truth time index" if at_truth else "scan"),
                        "curves")
        page.section("Metrics")
        if summary is not None:
            page.table(["metric", "value"], metric_rows(summary))
    _recording_sections(page, plots, tracks, details, sensor_set)
    page.section("Parameters and caps")
    page.table(None, _run_parameters(scenario, summary, seed)
               + ([] if scenario is not None else sensor_rows(sensor_set))
               + [(f"{k} file", p.name) for k, p in paths.items() if p is not None]
               + _caps_text((summary or {}).get("caps")), numbers=False)
    if truth is None and summary is None:
        page.note("No truth file: the page shows what the recording and its tracks say; "
                  "with truth (or metrics.json) it also shows the metrics. The tracker's "
                  "own parameters are those `mhtrack track` printed; tracks.csv does not "
                  "store them.")
    return page


def study_page(directory: Path) -> Page:
    """The page of a Monte-Carlo directory (module docstring)."""
    from mhtrack.experiments.montecarlo import load_results
    from mhtrack.reports.html_study import paired_figure, paired_rows, paired_table, tracker_table
    from mhtrack.reports.montecarlo import PAIRED_METRICS

    result = load_results(directory)
    spec = result.spec
    s = result.summary()
    title = f"Monte-Carlo: {spec.scenario_name}, {spec.runs} runs, base seed {spec.seed}"
    page = Page(f"mhtrack report: {title}", str(directory))
    curves = {t: v["per_scan"] for t, v in s.items() if v["per_scan"]["scans"]}
    page.section("Metrics over time")
    page.note("Mean over the successful runs per scan, band ± one (population) std.")
    if curves:
        page.figure(curves_figure(curves, cutoff=spec.run_kwargs.get("cutoff"),
                                  ospa2_window=spec.run_kwargs.get("ospa2_window")),
                    "curves")
    pairs, source = paired_rows(result, directory)
    if pairs:
        page.section("Paired comparisons")
        page.note(f"Run i of every tracker tracks the same simulated plots: A − B per run, "
                  f"its mean and 95 % t interval; the verdict is read from the interval "
                  f"(↑ higher is better, ↓ lower). Source: {source}.")
        page.figure(paired_figure(pairs), "paired")
        page.table(*paired_table(pairs, {k: d for k, (_, d) in PAIRED_METRICS.items()}))
        page.sentences([str(p["sentence"]) for p in pairs if p.get("sentence")])
    page.section("Metrics per tracker")
    page.note("Mean ± population std over the successful runs."
              + ("" if pairs else " No paired comparisons in this directory."))
    page.table(*tracker_table(result))
    page.section("Parameters and caps")
    rows = [("scenario", spec.scenario_name), ("trackers", ", ".join(spec.trackers)),
            ("runs per tracker", str(spec.runs)), ("base seed", str(spec.seed)),
            ("tracker configuration", json.dumps(spec.config, sort_keys=True) or "{}"),
            ("run keywords", json.dumps(spec.run_kwargs, sort_keys=True))]
    capped = result.runs_with_caps()
    rows += [(f"runs where a hard cap acted: {t}", f"{n} of {len(result.records[t])}")
             for t, n in capped.items()]
    failed = [(t, i) for t in spec.trackers for i in s[t]["failed"]]
    rows += [(f"failed: {t} run {i}", f"runs/{t}/run-{i}.error.txt") for t, i in failed]
    rows += [(f"missing: {t} run {i}", "not run") for t, i in result.missing]
    page.table(None, rows, numbers=False)
    return page


def report_page(directory: str | Path, stages: Stages | None = None, *,
                coastlines: bool = False) -> Page:
    """The page of ``directory``: a study when it holds ``montecarlo.json``, else a run
    (``coastlines``: :func:`run_page`)."""
    directory = Path(directory)
    require_plotly()
    if not directory.is_dir():
        raise FileNotFoundError(f"{directory}: no such directory")
    if (directory / STUDY_FILE).is_file():
        return study_page(directory)
    return run_page(directory, stages, coastlines=coastlines)


def write_html_report(directory: str | Path, out: str | Path | None = None, *,
                      plotlyjs: str = "inline", progress: bool = False,
                      coastlines: bool = False) -> Path:
    """Write the report of ``directory`` to ``out`` (default ``DIR/report.html``),
    atomically; returns its path. ``plotlyjs="file"`` writes Plotly's JavaScript once
    beside the page (:func:`~mhtrack.reports.html_page.plotlyjs_name`, kept when already
    there) instead of inlining it. ``progress``: a bar over the stages on stderr.
    ``coastlines``: :func:`run_page`."""
    from plotly.offline import get_plotlyjs

    from mhtrack.reports.html_page import plotlyjs_name

    directory = Path(directory)
    path = Path(out) if out is not None else directory / REPORT_FILE
    run = Stages(RUN_STAGES + 1, "report", progress)
    try:
        text = run("render", report_page(directory, run, coastlines=coastlines).render,
                   plotlyjs)
        if plotlyjs == "file" and not (js := path.parent / plotlyjs_name()).is_file():
            atomic_write(js, get_plotlyjs())
        written = atomic_write(path, text)
    finally:
        run.close()
    log.info("report of %s: %s (%.1f MB)", directory, written, len(text) / 1e6)
    return written
