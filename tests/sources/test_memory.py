"""MemorySource: the scans PlotTable.scans yields, counted, with the rows of the file the
table was read from (checked against the file itself)."""

from __future__ import annotations

import numpy as np
import pyarrow.csv as pacsv

from mhtrack.io import read_plots, write_plots
from mhtrack.records import NO_PLOT
from mhtrack.scenario import preset, simulate
from mhtrack.scenario.overrides import apply_overrides
from mhtrack.sources.memory import MemorySource


def test_frames_counts_and_survey_of_a_scans_table():
    sim = simulate(apply_overrides(preset("crossing"), scans=6), seed=2)
    src = MemorySource(sim.plots, name="sim")
    frames = list(src)
    want = list(sim.plots.scans())
    assert [f.index for f in frames] == [w.index for w in want]
    assert all(np.array_equal(f.z, w.z) for f, w in zip(frames, want, strict=True))
    assert (src.stats.frames, src.stats.plots_out, src.stats.late_dropped) == (
        len(want), len(sim.plots), 0)
    sv = src.survey()
    assert sv.n_plots == len(sim.plots) and sv.n_frames == sim.plots.n_scans
    assert np.array_equal(src.file_rows(np.array([3, NO_PLOT])), [3, NO_PLOT])


def test_file_rows_of_timed_plots_name_the_files_own_rows(tmp_path):
    sc = apply_overrides(preset("opensky-radars"), scans=3)
    sim = simulate(sc, seed=1)
    write_plots(sim.plots, tmp_path / "p.csv")
    table = read_plots(tmp_path / "p.csv", sensors=sc.sensor_set())
    src = MemorySource(table, sensors=sc.sensor_set())
    assert src.timed
    rows = np.concatenate([f.rows for f in src])
    file_rows = src.file_rows(rows)
    t_file = np.asarray(pacsv.read_csv(tmp_path / "p.csv").column("time").to_numpy())
    # each frame's plot read back from the file's own row has that plot's time
    assert np.array_equal(t_file[file_rows], table.time[rows])
    assert sorted(file_rows.tolist()) == list(range(len(table)))
