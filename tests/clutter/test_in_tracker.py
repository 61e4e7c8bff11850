"""The estimators inside the MHT and the ``mhtrack clutter`` command."""

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from mhtrack.build import make_tracker
from mhtrack.cli.clutter_commands import clutter
from mhtrack.clutter import AGMMClutter, GMMClutter
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.names import TRACKERS
from mhtrack.scenario import preset, simulate


def test_registered_trackers() -> None:
    assert isinstance(make_tracker("mht-gmm").clutter, GMMClutter)
    assert isinstance(make_tracker("mht-agmm").clutter, AGMMClutter)
    assert {"mht", "mht-gmm", "mht-agmm"} <= set(TRACKERS)


def test_tracker_state_with_agmm_round_trips(tmp_path: Path) -> None:
    sim = simulate(preset("crossing", scans=8), seed=1)
    scans = list(sim.plots.scans())
    trk = MHTTracker(MHTConfig(), AGMMClutter())
    for s in scans[:5]:
        trk.step(s)
    trk.save(tmp_path / "state.npz")
    back = MHTTracker.load(tmp_path / "state.npz", clutter=AGMMClutter())
    z = scans[5].z
    np.testing.assert_array_equal(back.clutter.intensity(z), trk.clutter.intensity(z))
    for s in scans[5:]:
        a, b = trk.step(s), back.step(s)
        np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(back.clutter.intensity(z), trk.clutter.intensity(z))


class _Spy(AGMMClutter):
    """The AGMM, recording what the tracker tells it to forget."""

    def __init__(self) -> None:
        super().__init__()
        self.forgotten: list[np.ndarray] = []

    def forget(self, used: np.ndarray) -> None:
        self.forgotten.append(np.asarray(used).copy())
        super().forget(used)


def test_tracker_tells_the_estimator_the_confirmed_tracks_plots() -> None:
    """Each scan, ``forget`` gets a mask over that scan's plots marking exactly the plots
    the reported (confirmed) tracks used."""
    sim = simulate(preset("crossing", scans=30), seed=2)
    spy = _Spy()
    trk = MHTTracker(MHTConfig(), spy)
    n_marked = 0
    for scan in sim.plots.scans():
        out = trk.step(scan)
        used = spy.forgotten[-1]
        assert used.shape == (len(scan),)
        reported = out.plot[out.plot >= 0].astype(np.int64)
        np.testing.assert_array_equal(np.asarray(scan.rows)[used], np.sort(reported))
        n_marked += int(used.sum())
    assert n_marked > 40  # targets 1 and 4 live through scans 1–30: most of their plots


@pytest.mark.parametrize("estimator", ["known", "agmm"])
def test_cli_json_and_figure(tmp_path: Path, estimator: str) -> None:
    out = tmp_path / estimator
    res = CliRunner().invoke(clutter, [
        "crossing", "--estimator", estimator, "--seed", "1", "--scans", "6",
        "--resolution", "100", "--json", "--out", str(out),
    ])
    assert res.exit_code == 0, res.output
    d = json.loads(res.output)
    assert len(d["iae"]) == len(d["count_error"]) == 6
    assert d["iae_mean"] == pytest.approx(np.mean(d["iae"]))
    assert (out / "clutter.png").stat().st_size > 10_000
    assert json.loads((out / "clutter.json").read_text())["iae_mean"] == d["iae_mean"]
    if estimator == "known":  # S·λ/A: 40 plots over 64 km²
        assert d["clutter_density"] == pytest.approx(40 / 64e6)
        assert d["count_error_mean"] == pytest.approx(0.0, abs=1e-9)


def test_cli_rejects_a_scan_outside_the_run(tmp_path: Path) -> None:
    res = CliRunner().invoke(clutter, ["crossing", "--scans", "3", "--map-scan", "50",
                                       "--out", str(tmp_path)])
    assert res.exit_code != 0
    assert "--map-scan" in res.output


def test_two_targets_flying_together_are_not_taken_for_a_clump() -> None:
    """docs/examples/parallel-pair.toml: two targets 300 m apart in 20 uniform clutter plots
    per scan. Before ``forget`` and the BIC test the AGMM modelled the pair's plots as a
    clutter clump: seed 1 confirmed them 9 and 39 scans after birth; now both within 8."""
    from mhtrack.experiments.pipeline import run_scenario
    from mhtrack.scenario.spec import load_scenario

    example = Path(__file__).resolve().parents[2] / "docs" / "examples" / "parallel-pair.toml"
    r = run_scenario(load_scenario(example), 1, "mht-agmm")
    delay = np.asarray(r.summary()["delay"], float)
    assert len(delay) == 2 and np.all(delay <= 8)
