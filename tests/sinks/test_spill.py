"""The tracks file streamed as frames complete (:mod:`mhtrack.sinks.spill`) has the bytes
of the former path — all rows collected (:class:`TrackCollector`), mapped to the input's
rows and written at once — and a failed run leaves neither the file nor a temporary."""

from __future__ import annotations

import dataclasses
import os

import numpy as np
import pyarrow.parquet as pq
import pytest

from mhtrack.io import write_plots
from mhtrack.io.atomic import is_temporary
from mhtrack.io.sensors import write_sensors
from mhtrack.io.tracks import write_track_rows
from mhtrack.pipeline import Pipeline, TrackOptions
from mhtrack.scenario import preset, simulate
from mhtrack.scenario.overrides import apply_overrides
from mhtrack.sinks import CallbackSink, TrackCollector, TracksFileSink
from mhtrack.sinks.spill import SortedRows

CHUNK = 7  # rows per chunk: many chunks, so the streaming path is exercised


@pytest.fixture(scope="module", params=[False, True], ids=["plain", "attributes"])
def plots_dir(tmp_path_factory, request):
    """The plots of opensky-radars, without and with secondary-radar attributes (then
    the tracks file has the attribute columns: :mod:`mhtrack.io.track_attributes`)."""
    from mhtrack.scenario.identity import AttributeOptions, add_attributes, opensky_identities

    d = tmp_path_factory.mktemp("rec")
    sc = apply_overrides(preset("opensky-radars"), scans=5)
    plots = simulate(sc, seed=1).plots
    if request.param:
        plots = add_attributes(plots, opensky_identities(), AttributeOptions(), 1)
    write_plots(plots, d / "plots.csv")
    write_sensors(sc.sensor_set(), d / "sensors.toml")
    return d


def _former(pipe: Pipeline, rows: TrackCollector, path, chunk: int | None) -> None:
    """The former sink: every row in memory, file rows mapped and written at the end."""
    t = rows.tracks()
    t = dataclasses.replace(t, plot=np.asarray(pipe.source.file_rows(t.plot), np.int64))
    kw = {} if chunk is None else {"row_group_size": chunk}
    write_track_rows(t, path, pipe.frame, timed=True, iso=pipe.source.iso_times, **kw)


@pytest.mark.parametrize("output", ["history", "online"])
@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_streamed_file_has_the_bytes_of_the_in_memory_path(plots_dir, tmp_path, output,
                                                           suffix):
    pipe = Pipeline.open(str(plots_dir / "plots.csv"), TrackOptions(output=output))
    out = tmp_path / f"tracks{suffix}"
    sink = TracksFileSink(out, frame=pipe.frame, output=pipe.output, chunk_rows=CHUNK)
    rows = TrackCollector(output)
    seen: list[bool] = []

    def look(_):  # during the run: a temporary beside the file, and no file yet
        seen.append(any(is_temporary(n) for n in os.listdir(tmp_path)) and not out.exists())

    pipe.run([sink, rows, CallbackSink(look)])
    assert any(seen), "the rows were never streamed to a temporary"
    with_attrs = "callsign" in pq.read_table(out).column_names if suffix == ".parquet" \
        else "callsign" in out.read_text().splitlines()[0]
    assert with_attrs == (rows.tracks().attrs is not None)
    assert len(rows.tracks()) > 10 * CHUNK
    _former(pipe, rows, tmp_path / f"ref{suffix}", CHUNK)
    assert out.read_bytes() == (tmp_path / f"ref{suffix}").read_bytes()
    _former(pipe, rows, tmp_path / f"old{suffix}", None)  # pyarrow's default row groups
    if suffix == ".csv":
        assert out.read_bytes() == (tmp_path / f"old{suffix}").read_bytes()
    else:
        assert pq.read_table(out).equals(pq.read_table(tmp_path / f"old{suffix}"))
        assert pq.ParquetFile(out).metadata.num_row_groups > 1
    assert not [n for n in os.listdir(tmp_path) if is_temporary(n)]


def test_sorted_rows_release_the_whole_sort_in_pieces():
    rng = np.random.default_rng(3)
    s = SortedRows()
    parts, out = [], []
    for k in range(40):  # frame k: rows of scans k-3 .. k (a backfill 3 frames back)
        n = int(rng.integers(0, 6))
        scan = np.maximum(k - rng.integers(0, 4, n), 0)
        t = _table(scan, rng.integers(0, 5, n), rng.normal(size=n))
        parts.append(t)
        if (got := s.push(t, max(k - 2, 0))) is not None:
            out.append(got)
    if (got := s.flush()) is not None:
        out.append(got)
    from mhtrack.records import TrackTable

    whole = TrackTable.concat(parts).sorted()
    got = TrackTable.concat(out)
    for f in ("scan", "track_id", "x"):
        assert np.array_equal(getattr(got, f), getattr(whole, f))


def test_a_row_before_the_settled_scans_is_refused():
    s = SortedRows()
    s.push(_table([5], [1], [0.0]), 5)
    with pytest.raises(RuntimeError, match="scan 4"):
        s.push(_table([4], [1], [0.0]), 5)


def _table(scan, tid, x):
    from mhtrack.records import TrackTable

    scan = np.asarray(scan, np.int64)
    z = np.asarray(x, float)
    return TrackTable(scan=scan, time=scan.astype(float), track_id=np.asarray(tid, np.int64),
                      x=z, y=z, vx=z, vy=z, plot=np.full(scan.size, -1, np.int64))


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_failed_run_leaves_no_file_and_no_temporary(plots_dir, tmp_path, suffix):
    pipe = Pipeline.open(str(plots_dir / "plots.csv"), TrackOptions(output="history"))
    out = tmp_path / f"tracks{suffix}"
    sink = TracksFileSink(out, frame=pipe.frame, output=pipe.output, chunk_rows=CHUNK)
    n = [0]

    def fail(_):
        n[0] += 1
        if any(is_temporary(f) for f in os.listdir(tmp_path)):
            raise OSError(5, "the recording went away")

    with pytest.raises(OSError, match="went away"):
        pipe.run([sink, CallbackSink(fail)])
    assert n[0] > 1 and os.listdir(tmp_path) == []
