"""``mhtrack live`` takes the young-track options (``--defer-tentative``,
``--startup-density``) and the clutter estimator's (``--clutter-half-life``,
``--clutter-forgetting``, ``--birth-scaling``, ``--map-range-cell``, ``--map-sectors``)
through the same option helpers as ``track``: a 5-scan ``opensky-radars`` recording read
by ``live`` from stdin (a file; in-process, no network) gives, with each option, the rows
of ``track --output online`` with the same option, and its final checkpoint holds the
tracker of the pipeline ``track`` runs with the option's field set — to the bit — which
is not the tracker without it (so ``live`` cannot pass by ignoring the option: on these
recordings the options change the tracks' scores and existence, not the rows ``live``
prints; ``--defer-tentative`` changes the tracker's state only with ``--nscan 1`` on a
recording with a clutter burst). A restart from a checkpoint with other options is
refused in one line; with the same ones it goes on."""

from __future__ import annotations

import csv
import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

pytest.importorskip("asterix.generated", reason="libasterix not installed")

from sim_recording import simulated_recording  # tests/helpers

from mhtrack.cli.main import cli
from mhtrack.mht import MHTTracker
from mhtrack.pipeline import Pipeline, TrackOptions
from mhtrack.pipeline.checkpoint import read_checkpoint

DENSITY = "1e-10"
MAP = ("--tracker", "mht-map")
#: Recordings: ``simulate opensky-radars`` options, the birth density tracked with.
SCENES = {"plain": ((), DENSITY), "burst": (("--clutter-scene", "burst"), "1e-8")}
#: (the recording, the options, their TrackOptions fields, the fields the option under
#: test sets — the run it is compared with has the others).
CASES = [
    ("burst", ("--nscan", "1", "--defer-tentative"), {"n_scan": 1, "defer_tentative": True},
     ("defer_tentative",)),
    ("plain", ("--startup-density",), {"startup_density": True}, ("startup_density",)),
    ("plain", (*MAP, "--clutter-half-life", "5"),
     {"tracker": "mht-map", "clutter_params": {"half_life": 5.0}}, ("clutter_params",)),
    ("plain", (*MAP, "--clutter-forgetting", "0.5"),
     {"tracker": "mht-map", "clutter_params": {"forgetting": 0.5}}, ("clutter_params",)),
    ("plain", (*MAP, "--birth-scaling", "1", "--map-sectors", "8", "--map-range-cell",
               "3000"),
     {"tracker": "mht-map", "clutter_params": {"birth_scaling": 1.0, "n_azimuth": 8,
                                               "range_cell": 3000.0}}, ("clutter_params",)),
    ("plain", ("--tracker", "mht-mapgmm", "--clutter-half-life", "5"),
     {"tracker": "mht-mapgmm", "clutter_params": {"half_life": 5.0}}, ("clutter_params",)),
]


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], Path]:
    """The recording of a scene (:data:`SCENES`), made once when first asked for."""
    made: dict[str, Path] = {}

    def get(name: str) -> Path:
        if name not in made:
            made[name] = simulated_recording(tmp_path_factory.mktemp(name), seed=2,
                                             scans=5, simulate=SCENES[name][0])
        return made[name]
    return get


@pytest.fixture(scope="module")
def rec(recording: Callable[[str], Path]) -> Path:
    return recording("plain")


def _track(rec: Path, out: Path, *options: str, density: str = DENSITY
           ) -> list[dict[str, float]]:
    """``track --output online`` rows (``frame``, ``track_id``, ``time``, ``x``, ``y``)."""
    r = CliRunner().invoke(cli, ["track", str(rec / "radar.ast"), "--sensors",
                                 str(rec / "sensors.toml"), "--output", "online",
                                 "--birth-density", density, "--out", str(out), "-q",
                                 *options])
    assert r.exit_code == 0, r.output
    with out.open() as fh:
        return [{k: float(row[k]) for k in ("frame", "track_id", "time", "x", "y")}
                for row in csv.DictReader(fh)]


def _live(rec: Path, *options: str, blocks: Path | None = None, density: str = DENSITY
          ) -> tuple[int, list[dict[str, float]], str]:
    """``live --stdin raw`` on ``blocks`` (default the recording) as its stdin, a file:
    the exit code, the JSON rows and what it said on stderr."""
    with (blocks or rec / "radar.ast").open("rb") as stdin:
        r = CliRunner().invoke(cli, ["live", "--stdin", "raw", "--sensors",
                                     str(rec / "sensors.toml"), "--day-from", "stream",
                                     "--birth-density", density, "--json", "--no-preload",
                                     *options], input=stdin)
    rows = [json.loads(x) for x in r.stdout.splitlines()]
    return r.exit_code, rows, r.stderr


def _same(got: list[dict[str, float]], ref: list[dict[str, float]]) -> None:
    assert [(r["frame"], r["track_id"]) for r in got] == \
        [(r["frame"], r["track_id"]) for r in ref]
    for col in ("x", "y", "time"):  # JSON and CSV round differently
        assert np.abs(np.array([r[col] for r in got])
                      - np.array([r[col] for r in ref])).max() <= 5e-4, col


def _final(rec: Path, density: str, **fields: object) -> MHTTracker:
    """The tracker at the end of the recording, run by the pipeline ``track`` runs
    (:meth:`Pipeline.open`), with these :class:`TrackOptions` fields."""
    pipe = Pipeline.open(str(rec / "radar.ast"), TrackOptions(
        output="online", new_target_density=float(density), **fields),  # type: ignore[arg-type]
        sensors_file=str(rec / "sensors.toml"))
    pipe.run([])
    return pipe.tracker


def _leaves(tracker: MHTTracker) -> tuple[list[float], ...]:
    lv = tracker.leaves
    return lv.score.tolist(), lv.x.ravel().tolist(), lv.track.tolist()


@pytest.mark.parametrize(("scene", "options", "fields", "own"), CASES,
                         ids=[" ".join(c[1]) for c in CASES])
def test_live_with_an_option_equals_track_online_with_it(
        recording: Callable[[str], Path], tmp_path: Path, scene: str, options: tuple[str, ...],
        fields: dict[str, object], own: tuple[str, ...]) -> None:
    """Rows as ``track``'s with the option; the final checkpoint's tracker is the
    pipeline's with the option's field set — its leaves (scores, states, track ids)
    to the bit, and its configuration and clutter estimator's keywords — and not the
    pipeline's without it."""
    rec, density = recording(scene), SCENES[scene][1]
    ref = _track(rec, tmp_path / "with.csv", *options, density=density)
    ck = tmp_path / "state.npz"
    code, rows, err = _live(rec, *options, "--checkpoint", str(ck), density=density)
    assert code == 0, err
    assert len(rows) > 100
    _same(rows, ref)
    tracker, state = read_checkpoint(ck)
    assert _leaves(tracker) == _leaves(_final(rec, density, **fields))
    assert _leaves(tracker) != _leaves(_final(rec, density, **{
        k: v for k, v in fields.items() if k not in own}))  # the option changes them
    flags = set(options)
    assert tracker.config.defer_tentative == ("--defer-tentative" in flags)
    assert tracker.config.startup_density == ("--startup-density" in flags)
    assert tracker.recipe["name"] == fields.get("tracker", "mht-agmm")
    assert tracker.recipe.get("clutter_params") == fields.get("clutter_params")
    assert state.options is not None
    assert {k: state.options[k] for k in fields} == fields  # what a restart is checked on


def test_usage_errors_as_track(rec: Path) -> None:
    """The same conflicts as ``track``, in the same words, before anything is read."""
    for options, words in [
            (("--birth", "logic", "--startup-density"),
             "--startup-density goes with --birth every-plot (not logic)"),
            (("--clutter-forgetting", "0.5"),
             "--clutter-forgetting goes with --tracker mht-map or mht-fgmm or mht-mapgmm "
             "(not mht-agmm)"),
            ((*MAP, "--clutter-forgetting", "0.5", "--clutter-half-life", "9"),
             "--clutter-forgetting or --clutter-half-life, not both")]:
        code, rows, err = _live(rec, *options)
        assert code == 2 and rows == [], err
        assert words in err


def test_a_restart_with_other_options_is_refused(rec: Path, tmp_path: Path) -> None:
    """The checkpoint of a ``--defer-tentative`` run: resumed with it, the run goes on;
    without it, or with another clutter estimator's option, refused in one line naming
    the checkpoint and the field (the saved tracker would keep the old options)."""
    ck = tmp_path / "state.npz"
    empty = tmp_path / "empty.ast"
    empty.write_bytes(b"")
    code, rows, err = _live(rec, *MAP, "--defer-tentative", "--checkpoint", str(ck))
    assert code == 0 and rows, err
    code, _, err = _live(rec, *MAP, "--defer-tentative", "--checkpoint", str(ck),
                         "--resume", blocks=empty)
    assert code == 0 and f"resumed from {ck}" in err, err
    for other, field in [((*MAP,), "defer_tentative True there, None here"),
                         ((*MAP, "--defer-tentative", "--clutter-half-life", "5"),
                          "clutter_params None there, {'half_life': 5.0} here")]:
        code, rows, err = _live(rec, *other, "--checkpoint", str(ck), "--resume",
                                blocks=empty)
        assert code == 2 and rows == [], err  # a user error: one line
        lines = err.strip().splitlines()
        assert len(lines) == 1 and str(ck) in lines[0] and field in lines[0], err
        assert "resume with the same options" in lines[0]


def test_sector_frames_as_track(rec: Path, tmp_path: Path) -> None:
    """``live --sector-frames`` gives ``track --sector-frames``'s online rows, not those
    without the flag."""
    ref = _track(rec, tmp_path / "sectors.csv", "--sector-frames")
    code, rows, err = _live(rec, "--sector-frames")
    assert code == 0, err
    assert len(rows) > 100
    _same(rows, ref)
    plain = _track(rec, tmp_path / "plain.csv")
    assert [r["frame"] for r in plain] != [r["frame"] for r in ref]
