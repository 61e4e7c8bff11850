"""The CAT062 sink writes the bytes ``export --category 062`` writes of the tracks file
of the same run (the former path: tracks file, then export)."""

from __future__ import annotations

import pytest

pytest.importorskip("asterix")

from mhtrack.io import write_plots
from mhtrack.io.asterix.cat062_export import export_tracks
from mhtrack.io.sensors import write_sensors
from mhtrack.pipeline import Pipeline, TrackOptions
from mhtrack.scenario import preset, simulate
from mhtrack.scenario.overrides import apply_overrides
from mhtrack.sinks import Cat062Sink, TracksFileSink


def test_cat062_sink_equals_export_of_the_tracks_file(tmp_path):
    sc = apply_overrides(preset("opensky-radars"), scans=6)
    sim = simulate(sc, seed=1)
    write_plots(sim.plots, tmp_path / "plots.csv")
    write_sensors(sc.sensor_set(), tmp_path / "sensors.toml")  # found beside the plots
    pipe = Pipeline.open(str(tmp_path / "plots.csv"), TrackOptions())
    assert pipe.source.timed and pipe.frame is not None and pipe.fusion == "none"
    table = TracksFileSink(tmp_path / "tracks.csv", frame=pipe.frame)
    cat = Cat062Sink(tmp_path / "sink.pcap", pipe.frame, sac=7, sic=9)
    result = pipe.run([table, cat])
    assert result.n_tracks > 0 and result.timed
    n, blocks = export_tracks(tmp_path / "tracks.csv", None, tmp_path / "export.pcap",
                              sac=7, sic=9)
    assert cat.n_blocks == blocks and n > 0
    assert (tmp_path / "sink.pcap").read_bytes() == (tmp_path / "export.pcap").read_bytes()


def test_open_input_refuses_a_scenario_for_timed_plots(tmp_path):
    sc = apply_overrides(preset("opensky-radars"), scans=2)
    write_plots(simulate(sc, seed=1).plots, tmp_path / "plots.csv")
    (tmp_path / "scenario.toml").write_text("")
    with pytest.raises(ValueError, match="holds timed plots"):
        Pipeline.open(str(tmp_path / "plots.csv"), scenario_file=str(tmp_path / "scenario.toml"))
