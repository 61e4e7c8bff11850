"""The tracking pipeline: simulate → build → track → evaluate, and the builder's defaults on
real aircraft."""

import logging

import numpy as np
import pytest

from mhtrack.build import default_config, make_tracker
from mhtrack.experiments.pipeline import run_scenario, track
from mhtrack.metrics import evaluate
from mhtrack.scenario import preset, simulate


def test_run_scenario_is_simulate_build_track_evaluate():
    """run_scenario's tracks are those of the builder's tracker run by ``track`` on the
    simulation, and its evaluation scores them."""
    sc = preset("crossing", scans=12)
    r = run_scenario(sc, 4, "mht", clutter_density=2e-9)
    sim = simulate(sc, seed=4)
    trk = make_tracker("mht", default_config(sc), clutter_density=2e-9)
    want = track(trk, sim.plots, name="mht").tracks
    for f in ("scan", "track_id", "x", "y", "plot", "tentative"):
        np.testing.assert_array_equal(getattr(r.run.tracks, f), getattr(want, f))
    assert r.summary()["ospa"] == evaluate(want, sim.truth, plots=sim.plots).to_dict()["ospa"]
    assert r.summary()["tracker"] == "mht" and r.summary()["output"] == "history"


def test_unknown_fusion_or_output():
    trk = make_tracker("mht")
    scans = simulate(preset("crossing", scans=2), seed=0).plots
    with pytest.raises(ValueError, match="unknown fusion 'kmeans'"):
        track(trk, scans, fusion="kmeans")
    with pytest.raises(ValueError, match=r"unknown output 'all'.*history, online"):
        track(trk, scans, output="all")


def test_real_aircraft_are_tracked_with_the_defaults(caplog):
    """OpenSky: 84 real aircraft, 10 s scans, two radars. With P1's λv taken literally
    (1e−7 per m² over ~2.9e11 m²) every plot became a confirmed track (5 809 tracks);
    with the scaled default the tracks are about one per aircraft."""
    sc = preset("opensky")
    assert default_config(sc).new_target_density < 1e-10
    with caplog.at_level(logging.ERROR):
        r = run_scenario(sc, 1, "mht-agmm", cutoff=2000.0)
    s = r.summary()
    assert 84 <= s["n_tracks"] <= 110
    assert s["mota"] > 0.85
    assert s["rcc"] > 0.9
    assert s["id_switches"] < 40


def test_run_scenario_tracks_rotating_radars_as_track_sensors_does():
    # A scenario of rotating radars: run_scenario must track its timed plots frame by
    # frame with the radars' coverage, exactly as `mhtrack track --sensors` does.
    from mhtrack.mht.coverage import RadarCoverage

    sc = preset("opensky-radars", scans=4)
    run = run_scenario(sc, 1, "mht-agmm")
    assert run.simulation.plots.timed
    trk = make_tracker("mht-agmm", default_config(sc), sensors=sc.sensor_set())
    assert isinstance(trk.coverage, RadarCoverage)
    direct = track(trk, run.simulation.plots, name="mht-agmm")
    assert len(run.run.tracks) > 0
    assert run.run.tracks.track_id.tolist() == direct.tracks.track_id.tolist()
    assert run.run.tracks.x.tolist() == direct.tracks.x.tolist()
