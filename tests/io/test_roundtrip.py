"""Write → read round trips of plots, truth and tracks tables (CSV and Parquet), exact to
the bit, and the on-disk CSV text of a small table."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mhtrack.io import (
    read_plots,
    read_tracks,
    read_truth,
    write_plots,
    write_tracks,
    write_truth,
)
from mhtrack.io.plots import MAX_GAP
from mhtrack.models.sensors import CartesianSensor, PolarRadar
from mhtrack.records import PlotTable, TrackTable, TruthTable

FORMATS = ["csv", "parquet"]
SETTINGS = settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)

# within the readers' bounds (mhtrack.bounds): |float| <= 1e15, |time| <= 1e12 s,
# |integer| <= 2^53
finite = st.floats(-1e15, 1e15, allow_nan=False, allow_infinity=False)
times_s = st.floats(-1e12, 1e12, allow_nan=False, allow_infinity=False)
int64 = st.integers(-(2**53), 2**53)


def same_bits(want: np.ndarray, got: np.ndarray) -> bool:
    """Exact equality with the in-memory dtype (int64 / float64), bit for bit: -0.0 is not
    0.0, and NaN only matches NaN."""
    want, got = np.asarray(want), np.asarray(got)
    if got.shape != want.shape:
        return False
    if want.dtype.kind == "f":
        nan = np.isnan(want)
        return (
            got.dtype == np.float64
            and np.array_equal(nan, np.isnan(got))
            and np.array_equal(want[~nan].view(np.int64), got[~nan].view(np.int64))
        )
    return got.dtype == np.int64 and np.array_equal(want, got)


@st.composite
def scans_and_times(
    draw: st.DrawFn, min_scans: int = 0, max_step: int | None = None
) -> list[tuple[int, float]]:
    """Strictly increasing scan indices with strictly increasing times; with ``max_step``,
    consecutive scan indices at most that far apart (plots files bound the gaps)."""
    if max_step is None:
        scans = sorted(draw(st.sets(int64, min_size=min_scans, max_size=8)))
    else:
        steps = draw(st.lists(st.integers(1, max_step), min_size=max(min_scans - 1, 0),
                              max_size=7))
        first = draw(st.integers(-(2**53), 2**53 - sum(steps)))
        scans = [first + sum(steps[:i]) for i in range(len(steps) + 1)]
    times = sorted(draw(st.sets(times_s, min_size=len(scans), max_size=len(scans))))
    return list(zip(scans, times, strict=True))


@st.composite
def plot_tables(draw: st.DrawFn) -> PlotTable:
    rows = []
    for k, t in draw(scans_and_times(min_scans=1, max_step=MAX_GAP // 7 + 1)):
        rows += [(k, t)] * draw(st.integers(1, 4))
    n = len(rows)
    polar = draw(st.booleans())
    with_origin = draw(st.booleans())
    sensor = np.array(draw(st.lists(st.integers(0, 3), min_size=n, max_size=n)), np.int64)
    floats = st.lists(finite, min_size=n, max_size=n)
    # plot positions within the readers' ±1e9 m (records.MAX_COORDINATE)
    coords = st.lists(st.floats(-1e9, 1e9), min_size=n, max_size=n)
    rng = bearing = None
    if polar:  # sensors 0, 1 are polar; 2, 3 Cartesian with empty range/bearing
        cart = sensor >= 2
        ranges = st.floats(0.0, 1e15)  # the readers' bound (mhtrack.bounds)
        rng = np.where(cart, np.nan, draw(st.lists(ranges, min_size=n, max_size=n)))
        bearing = np.where(cart, np.nan, draw(floats))
    return PlotTable(
        scan=np.array([r[0] for r in rows], np.int64),
        time=np.array([r[1] for r in rows], np.float64),
        sensor=sensor,
        x=np.array(draw(coords)),
        y=np.array(draw(coords)),
        range=rng,
        bearing=bearing,
        origin=np.array(draw(st.lists(st.integers(-1, 2**53), min_size=n, max_size=n)))
        if with_origin
        else None,
    )


REGISTRY = {
    0: PolarRadar(0),
    1: PolarRadar(1, (10.0, -5.0)),
    2: CartesianSensor(2),
    3: CartesianSensor(3),
}


@pytest.mark.parametrize("fmt", FORMATS)
@SETTINGS
@given(table=plot_tables())
def test_plots_round_trip(tmp_path, fmt: str, table: PlotTable) -> None:
    path = tmp_path / f"plots.{fmt}"
    write_plots(table, path)
    back = read_plots(path, sensors=REGISTRY if table.range is not None else None)
    for name in ("scan", "time", "sensor", "x", "y"):
        assert same_bits(getattr(table, name), getattr(back, name)), name
    for name in ("range", "bearing", "origin"):
        want, got = getattr(table, name), getattr(back, name)
        assert (want is None) == (got is None), name
        if want is not None:
            assert same_bits(want, got), name
    assert back.scan_times is None


@st.composite
def truth_tables(draw: st.DrawFn) -> TruthTable:
    cols: dict[str, list] = {c: [] for c in ("scan", "time", "target_id")}
    for k, t in draw(scans_and_times()):
        ids = sorted(draw(st.sets(st.integers(0, 2**53), min_size=1, max_size=4)))
        cols["scan"] += [k] * len(ids)
        cols["time"] += [t] * len(ids)
        cols["target_id"] += ids
    n = len(cols["scan"])
    floats = {c: np.array(draw(st.lists(finite, min_size=n, max_size=n)), np.float64)
              for c in ("x", "y", "vx", "vy")}  # fmt: skip
    return TruthTable(
        scan=np.array(cols["scan"], np.int64),
        time=np.array(cols["time"], np.float64),
        target_id=np.array(cols["target_id"], np.int64),
        **floats,
    )


@pytest.mark.parametrize("fmt", FORMATS)
@SETTINGS
@given(table=truth_tables())
def test_truth_round_trip(tmp_path, fmt: str, table: TruthTable) -> None:
    path = tmp_path / f"truth.{fmt}"
    write_truth(table, path)
    back = read_truth(path)
    for name in ("scan", "time", "target_id", "x", "y", "vx", "vy"):
        assert same_bits(getattr(table, name), getattr(back, name)), name


@st.composite
def track_tables(draw: st.DrawFn) -> TrackTable:
    cols: dict[str, list] = {c: [] for c in ("scan", "time", "track_id")}
    for k, t in draw(scans_and_times()):
        ids = draw(st.lists(int64, min_size=1, max_size=4, unique=True))  # any order
        cols["scan"] += [k] * len(ids)
        cols["time"] += [t] * len(ids)
        cols["track_id"] += ids
    n = len(cols["scan"])
    floats = {c: np.array(draw(st.lists(finite, min_size=n, max_size=n)), np.float64)
              for c in ("x", "y", "vx", "vy")}  # fmt: skip
    plot = st.one_of(st.just(-1), st.integers(0, 2**53))
    score = np.array(draw(st.lists(finite, min_size=n, max_size=n)), np.float64)
    return TrackTable(
        scan=np.array(cols["scan"], np.int64),
        time=np.array(cols["time"], np.float64),
        track_id=np.array(cols["track_id"], np.int64),
        plot=np.array(draw(st.lists(plot, min_size=n, max_size=n)), np.int64),
        score=score if draw(st.booleans()) else None,
        tentative=(np.array(draw(st.lists(st.booleans(), min_size=n, max_size=n)), bool)
                   if draw(st.booleans()) else None),
        **floats,
    )


@pytest.mark.parametrize("fmt", FORMATS)
@SETTINGS
@given(table=track_tables())
def test_tracks_round_trip(tmp_path, fmt: str, table: TrackTable) -> None:
    path = tmp_path / f"tracks.{fmt}"
    write_tracks(table, path)
    back = read_tracks(path)
    for name in ("scan", "time", "track_id", "x", "y", "vx", "vy", "plot"):
        assert same_bits(getattr(table, name), getattr(back, name)), name
    assert (back.score is None) == (table.score is None)
    if table.score is not None:
        assert same_bits(table.score, back.score)
    assert (back.tentative is None) == (table.tentative is None)
    if table.tentative is not None:
        assert np.array_equal(back.tentative, table.tentative)
    assert back.P is None


@pytest.mark.parametrize("fmt", FORMATS)
def test_empty_tracks_and_truth_round_trip(tmp_path, fmt: str) -> None:
    write_tracks(TrackTable.empty(), tmp_path / f"t.{fmt}")
    tracks = read_tracks(tmp_path / f"t.{fmt}")
    assert len(tracks) == 0
    assert tracks.plot.dtype == np.int64
    assert tracks.x.dtype == np.float64
    e, i = np.zeros(0), np.zeros(0, np.int64)
    write_truth(TruthTable(i, e, i, e, e, e, e), tmp_path / f"g.{fmt}")
    assert len(read_truth(tmp_path / f"g.{fmt}")) == 0


def test_csv_text_is_plain_and_misses_are_empty(tmp_path) -> None:
    table = TrackTable(
        scan=np.array([1, 2]),
        time=np.array([0.5, 1.5]),
        track_id=np.array([3, 3]),
        x=np.array([0.1, 1e22]),
        y=np.array([-2.0, 1 / 3]),
        vx=np.array([0.0, -0.0]),
        vy=np.array([5e-324, 2.5e-7]),
        plot=np.array([-1, 12]),
        score=np.array([1.25, -3.0]),
    )
    path = tmp_path / "tracks.csv"
    write_tracks(table, path)
    assert path.read_text() == (
        "scan,time,track_id,x,y,vx,vy,plot,score\n"
        "1,0.5,3,0.1,-2,0,5e-324,,1.25\n"
        "2,1.5,3,1e+22,0.3333333333333333,-0,2.5e-7,12,-3\n"
    )


def test_plots_csv_writes_nan_range_as_empty_cell(tmp_path) -> None:
    table = PlotTable(
        scan=np.array([4, 4]),
        time=np.array([2.0, 2.0]),
        sensor=np.array([0, 5]),
        x=np.array([1.0, 2.0]),
        y=np.array([3.0, 4.0]),
        range=np.array([100.0, np.nan]),
        bearing=np.array([45.0, np.nan]),
        origin=np.array([-1, 7]),
    )
    path = tmp_path / "plots.csv"
    write_plots(table, path)
    assert path.read_text() == (
        "scan,time,sensor,x,y,range,bearing,origin\n4,2,0,1,3,100,45,-1\n4,2,5,2,4,,,7\n"
    )
