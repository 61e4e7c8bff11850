"""The pipeline against the former code path: the tracker stepped by hand over the same
table (``MHTTracker.run``) and the tracks file written by ``io.write_tracks``."""

from __future__ import annotations

import numpy as np
import pytest

from mhtrack.build import default_config, default_fusion, make_tracker
from mhtrack.io import read_tracks, write_tracks
from mhtrack.pipeline import Pipeline, TrackOptions, fused
from mhtrack.scenario import preset, simulate
from mhtrack.scenario.overrides import apply_overrides
from mhtrack.sinks import CallbackSink, TrackCollector, TracksFileSink
from mhtrack.sources.memory import MemorySource


@pytest.fixture(scope="module")
def multiradar():
    sc = apply_overrides(preset("multiradar"), scans=12)
    return sc, simulate(sc, seed=3)


def _by_hand(sc, plots, output):
    """The former path: default config of the scenario, default fusion, tracker.run."""
    trk = make_tracker("mht-agmm", default_config(sc))
    scans = fused(plots.scans(), default_fusion(len(sc.sensors)))
    return trk.run(scans, history=output == "history")


@pytest.mark.parametrize("output", ["history", "online"])
def test_pipeline_equals_the_tracker_run_by_hand(multiradar, tmp_path, output):
    sc, sim = multiradar
    assert len(sc.sensors) > 1  # the fusion default is exercised
    pipe = Pipeline(MemorySource(sim.plots, scenario=sc), TrackOptions(output=output))
    rows, seen = TrackCollector(output), []
    sink = TracksFileSink(tmp_path / "t.csv", output=output)
    result = pipe.run([rows, sink, CallbackSink(seen.append)])
    want = _by_hand(sc, sim.plots, output)
    got = rows.tracks()
    for f in ("scan", "track_id", "x", "y", "vx", "vy", "plot"):
        assert np.array_equal(getattr(got, f), getattr(want, f)), f
    assert result.n_tracks == len(set(want.track_id.tolist()))
    assert len(seen) == len(result.stats) == sim.plots.n_scans
    assert [o.stats.scan for o in seen] == list(range(sc.first, sc.last + 1))
    write_tracks(want, tmp_path / "want.csv", plots=sim.plots)
    assert (tmp_path / "t.csv").read_bytes() == (tmp_path / "want.csv").read_bytes()


def test_rolling_parts_hold_the_rows_of_their_frames(multiradar, tmp_path):
    sc, sim = multiradar
    whole = TracksFileSink(tmp_path / "all.csv", output="online")
    parts = TracksFileSink(tmp_path / "t.csv", output="online", part_frames=5)
    Pipeline(MemorySource(sim.plots, scenario=sc), TrackOptions(output="online")).run(
        [whole, parts])
    n = sim.plots.n_scans
    assert [p.name for p in parts.paths] == [f"t.part{i:04d}.csv"
                                            for i in range(-(-n // 5))]
    back = [read_tracks(p) for p in parts.paths]
    first = sc.first
    for i, t in enumerate(back):  # each part: the online rows of its 5 frames
        assert set(t.scan.tolist()) <= set(range(first + 5 * i, first + 5 * i + 5))
    all_rows = read_tracks(tmp_path / "all.csv")
    assert np.array_equal(np.concatenate([t.track_id for t in back]), all_rows.track_id)
    assert np.array_equal(np.concatenate([t.x for t in back]), all_rows.x)


def test_options_conflicts_are_value_errors(multiradar):
    sc, sim = multiradar
    with pytest.raises(ValueError, match="clutter-density"):
        Pipeline(MemorySource(sim.plots, scenario=sc),
                 TrackOptions(tracker="mht-agmm", clutter_density=1e-9))
    with pytest.raises(ValueError, match="part_frames"):
        TracksFileSink("t.csv", part_frames=0)
