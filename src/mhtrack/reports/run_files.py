"""The files and the text of one ``mhtrack run``: plots, truth, tracks, scenario.toml,
metrics.json, scene.png and metrics.png in one directory (:func:`write_run`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from mhtrack.build import birth_suffix

if TYPE_CHECKING:
    from mhtrack.experiments.pipeline import ScenarioRun
    from mhtrack.scenario import Scenario

#: What each output mode (:data:`mhtrack.names.OUTPUTS`) reports, in words.
OUTPUT_TEXT = {"history": "history (each track also before its confirmation, rows marked "
               "tentative)", "online": "online (what the tracker reported at each scan)",
               "smoothed": "smoothed (the history, each track smoothed over all its rows)"}


def run_dir(scenario: Scenario, tracker: str, birth: str | None, seed: int) -> Path:
    """``out/SCENARIO-TRACKER[-BIRTH]-SEED`` (the birth named unless the default)."""
    return Path("out") / f"{scenario.name}-{tracker}{birth_suffix(birth)}-{seed}"


def write_run(out: Path, result: ScenarioRun, seed: int) -> dict[str, Any]:
    """Write the run's files to ``out`` (created); returns its summary
    (:meth:`ScenarioRun.summary`). Tracks and truth of geodetic radars carry lat/lon."""
    from mhtrack.io import write_plots, write_scenario_toml, write_tracks, write_truth
    from mhtrack.io.atomic import atomic_write
    from mhtrack.io.jsonsafe import dumps
    from mhtrack.plotting.metrics import plot_ospa_cardinality
    from mhtrack.plotting.scene import plot_scene, save_figure

    out.mkdir(parents=True, exist_ok=True)
    sim, sc, tracker = result.simulation, result.simulation.scenario, result.run.tracker
    frame = output_frame(sc, sim.plots)
    write_plots(sim.plots, out / "plots.csv")
    write_truth(sim.truth, out / "truth.csv", frame)
    write_tracks(result.run.tracks, out / "tracks.csv", frame, plots=sim.plots)
    write_scenario_toml({"seed": seed, **sc.to_dict()}, out / "scenario.toml")
    summary = result.summary()
    atomic_write(out / "metrics.json", dumps(summary, indent=1))
    title = f"{sc.name}, {tracker}, seed {seed}"
    save_figure(plot_scene(sim.plots, sim.truth, result.run.tracks, title=title),
                out / "scene.png")
    save_figure(plot_ospa_cardinality({tracker: summary}, cutoff=result.evaluation.cutoff,
                                      title=title), out / "metrics.png")
    return summary


def output_frame(sc: Scenario, plots: Any) -> Any:
    """The local frame of a simulation's geodetic radars (timed plots), for the lat/lon
    columns of its truth and tracks files; ``None`` for synchronous scans."""
    if not plots.timed:
        return None
    sensor_set = sc.sensor_set()
    return sensor_set.frame() if sensor_set.reference is not None else None


def run_text(result: ScenarioRun, out: Path) -> list[str]:
    """The lines ``mhtrack run`` prints after its run (not with ``--json``)."""
    lines = [result.evaluation.to_table(), "output: " + OUTPUT_TEXT[result.run.output],
             f"tracker time: {1e3 * result.run.t_avg:.2f} ms/scan (mean)"]
    if result.birth_note is not None:
        lines.append(result.birth_note)
    if result.run.caps:
        lines.append(f"hard caps acted: {result.run.caps}")
    lines.append(f"wrote {out}/ (plots, truth, tracks, metrics.json, scene.png, metrics.png)")
    return lines
