"""Timed plots files (no ``scan``): conversions checked against GeographicLib's own geodesics,
times against ``datetime``, frames against :func:`make_frames`, and write/read round trips."""

from __future__ import annotations

import logging
from dataclasses import fields, replace
from datetime import UTC, datetime, timedelta

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from geodesic_reference import WGS84
from site_sensors import ORIGIN, SITE, sensors_toml

from mhtrack.frames import frame_lengths, make_frames
from mhtrack.io import read_plots, write_plots
from mhtrack.io.plots import file_rows, plots_to_file_rows, plots_to_table_rows
from mhtrack.io.sensors import read_sensors
from mhtrack.models.radars import RadarSensor, SensorSet

SENSORS = sensors_toml()


@pytest.fixture
def sensors(tmp_path) -> SensorSet:
    path = tmp_path / "sensors.toml"
    path.write_text(SENSORS)
    return read_sensors(path)


def write(tmp_path, text: str, name: str = "plots.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def local_by_geographiclib(lat: float, lon: float) -> tuple[float, float]:
    """The azimuthal equidistant plane from first principles: distance and azimuth from the
    origin by GeographicLib's inverse problem, ``x = s sin α1``, ``y = s cos α1``."""
    g = WGS84.Inverse(*ORIGIN, lat, lon)
    a = np.radians(g["azi1"])
    return g["s12"] * np.sin(a), g["s12"] * np.cos(a)


def test_polar_and_geodetic_plots_match_geographiclib(tmp_path, sensors):
    plots = [(200_000.0, 10.0), (250_000.0, 97.5), (120_000.0, 301.25), (5.0, 0.0)]
    rows = [f"{i},1,{r!r},{b!r},," for i, (r, b) in enumerate(plots)]
    rows += ["4,2,,,47.9,9.95", "5,2,,,45.1,5.4"]
    t = read_plots(write(tmp_path, "time,sensor,range,bearing,lat,lon\n"
                         + "\n".join(rows) + "\n"), sensors=sensors)
    assert t.timed and t.file_row.tolist() == list(range(6))
    for i, (r, b) in enumerate(plots):
        d = WGS84.Direct(*SITE, b, r)
        assert np.hypot(t.x[i] - local_by_geographiclib(d["lat2"], d["lon2"])[0],
                        t.y[i] - local_by_geographiclib(d["lat2"], d["lon2"])[1]) < 1e-3
    for i, (lat, lon) in zip((4, 5), ((47.9, 9.95), (45.1, 5.4)), strict=True):
        assert np.allclose((t.x[i], t.y[i]), local_by_geographiclib(lat, lon), atol=1e-3)
        assert np.array_equal(t.R[i], 50.0**2 * np.eye(2))
    # Polar R = J diag(σr², σθ²) Jᵀ, J = ∂(x, y)/∂(r, θ) of GeographicLib's chain (direct
    # problem from the site, then the plane above) by central differences.
    def plot_xy(r: float, b: float) -> np.ndarray:
        d = WGS84.Direct(*SITE, b, r)
        return np.array(local_by_geographiclib(d["lat2"], d["lon2"]))

    r0, b0 = plots[0]
    jr = (plot_xy(r0 + 1.0, b0) - plot_xy(r0 - 1.0, b0)) / 2.0
    jt = (plot_xy(r0, b0 + 1e-3) - plot_xy(r0, b0 - 1e-3)) / np.radians(2e-3)
    J = np.column_stack((jr, jt))
    want = J @ np.diag([80.0**2, np.radians(0.15) ** 2]) @ J.T
    assert np.allclose(t.R[0], want, rtol=1e-5)
    assert np.allclose(t.range[:4], [r for r, _ in plots]) and np.isnan(t.range[4:]).all()


def iso(dt: datetime) -> str:
    return dt.isoformat(timespec="microseconds").replace("+00:00", "Z")


def test_iso_times_are_posix_seconds_as_datetime_says(tmp_path):
    rng = np.random.default_rng(3)
    t0 = datetime(2024, 5, 1, 12, 0, 3, 250_000, tzinfo=UTC)
    times = sorted(t0 + timedelta(microseconds=int(u)) for u in rng.integers(0, 10**7, 50))
    text = [iso(t) for t in times]
    text[7] = times[7].astimezone(datetime.strptime("+0130", "%z").tzinfo).isoformat()
    body = "".join(f"{s},1,{i},0\n" for i, s in enumerate(text))
    got = read_plots(write(tmp_path, "time,sensor,x,y\n" + body))
    want = np.array([t.timestamp() for t in times])
    # datetime.timestamp() is (t - epoch) / 1 s, correctly rounded; ours s + ns/1e9.
    back = np.empty(50)
    back[got.file_row] = got.time
    assert np.all(np.abs(back - want) <= np.spacing(want))
    assert got.timed and np.all(np.diff(got.time) >= 0)


def test_parquet_timestamps_equal_iso_text(tmp_path):
    base = np.datetime64("2024-05-01T12:00:03.250", "ms")
    stamps = base + np.array([0, 250, 1200, 5000], "timedelta64[ms]")
    cols = {"sensor": pa.array([1, 1, 1, 1]), "x": pa.array([0.0, 1, 2, 3]),
            "y": pa.array([0.0, 1, 2, 3])}
    for tz in ("UTC", None):
        time = pa.array(stamps, pa.timestamp("ms", tz=tz))
        pq.write_table(pa.table({"time": time, **cols}), tmp_path / "p.parquet")
        got = read_plots(tmp_path / "p.parquet")
        text = "".join(f"{np.datetime_as_string(s, unit='ms')}Z,1,{i},{i}\n"
                       for i, s in enumerate(stamps))
        assert np.array_equal(got.time,
                              read_plots(write(tmp_path, "time,sensor,x,y\n" + text)).time)
        assert got.time[0] == datetime(2024, 5, 1, 12, 0, 3, 250_000, tzinfo=UTC).timestamp()


def test_frames_are_make_frames_of_the_sensor_periods(tmp_path, sensors):
    rng = np.random.default_rng(0)
    n = 60
    time = np.sort(rng.uniform(0, 30, n))
    sensor = rng.choice([1, 2], n)
    body = "".join(f"{float(t)!r},{s},{'' if s == 2 else 1000.0 + i},{'' if s == 2 else 45.0},"
                   f"{i if s == 2 else ''},{0 if s == 2 else ''}\n"
                   for i, (t, s) in enumerate(zip(time, sensor, strict=True)))
    t = read_plots(write(tmp_path, "time,sensor,range,bearing,x,y\n" + body), sensors=sensors)
    frame, order = make_frames(time, sensor, frame_lengths({1: 12.0, 2: None}))
    assert np.array_equal(t.file_row, order) and np.array_equal(t.scan, frame[order])
    assert np.array_equal(t.time, time[order]) and np.array_equal(t.sensor, sensor[order])
    assert all(np.unique(t.sensor[t.scan == k]).size == 1 for k in np.unique(t.scan))


def table_equal(a, b) -> bool:
    for f in fields(a):
        va, vb = getattr(a, f.name), getattr(b, f.name)
        if (va is None) != (vb is None):
            return False
        if isinstance(va, np.ndarray) and not np.array_equal(va, vb, equal_nan=True):
            return False
        if not isinstance(va, np.ndarray) and va != vb:
            return False
    return True


@pytest.mark.parametrize("fmt", ["csv", "parquet"])
def test_timed_table_round_trip(tmp_path, sensors, fmt):
    body = ("time,sensor,range,bearing,x,y,origin\n"
            "0.5,1,150000.0,12.5,,,3\n0.25,2,,,100.0,-20.0,-1\n1.75,1,90000.0,271.0,,,-1\n"
            "1.0,2,,,150.0,-25.0,3\n13.0,1,151000.0,12.75,,,3\n")
    first = read_plots(write(tmp_path, body), sensors=sensors)
    path = tmp_path / f"again.{fmt}"
    write_plots(first, path)
    again = read_plots(path, sensors=sensors)
    assert table_equal(first, again)
    # Without file_row, a timed table is written in time order: the same table comes back.
    bare = replace(first, file_row=None)
    write_plots(bare, path)
    back = read_plots(path, sensors=sensors)
    assert table_equal(replace(back, file_row=None), bare)
    assert np.array_equal(back.file_row, np.argsort(np.argsort(bare.time, kind="stable")))
    assert "scan" not in (tmp_path / "again.csv").read_text().splitlines()[0].split(",") \
        if fmt == "csv" else "scan" not in pq.read_schema(path).names


def test_rows_out_of_order_within_the_window_give_the_sorted_table(tmp_path, sensors):
    rows = ["0.0,2,1,1", "0.5,2,2,2", "1.0,2,3,3", "1.5,2,4,4", "2.0,2,5,5", "2.5,2,6,6"]
    shuffled = [rows[i] for i in (1, 0, 3, 4, 2, 5)]  # "1.0" arrives 1 s late
    a = read_plots(write(tmp_path, "time,sensor,x,y\n" + "\n".join(rows) + "\n", "a.csv"))
    b = read_plots(write(tmp_path, "time,sensor,x,y\n" + "\n".join(shuffled) + "\n", "b.csv"),
                   sensors=None)
    assert table_equal(replace(a, file_row=None), replace(b, file_row=None))
    assert b.file_row.tolist() == [1, 0, 4, 2, 3, 5]
    # 0.5 s: "1.0" is 1 s before the latest but nothing after 0.5 had left the buffer
    c = read_plots(tmp_path / "b.csv", reorder_window_s=0.5)
    assert table_equal(replace(a, file_row=None), replace(c, file_row=None))


def test_rows_beyond_the_window_dropped_with_the_sources_warning(tmp_path, caplog):
    """0.2 s: "1.5" has left the buffer when "1.0" (line 6) arrives, so the row is
    dropped, with the warning ``track`` gives (before: the whole file was refused)."""
    rows = ["0.5,2,2,2", "0.0,2,1,1", "1.5,2,4,4", "2.0,2,5,5", "1.0,2,3,3", "2.5,2,6,6"]
    path = write(tmp_path, "time,sensor,x,y\n" + "\n".join(rows) + "\n", "b.csv")
    with caplog.at_level(logging.WARNING, logger="mhtrack"):
        t = read_plots(path, reorder_window_s=0.2)
    assert t.time.tolist() == [0.0, 0.5, 1.5, 2.0, 2.5]
    assert t.file_row.tolist() == [1, 0, 2, 3, 5]
    assert [r.getMessage() for r in caplog.records] == [
        f"{path}: 1 plot dropped, late by 1 s (after later plots had gone to the tracker, "
        "beyond the reorder window; first at line 6)"]


def test_track_plot_references_translate_both_ways(tmp_path):
    t = read_plots(write(tmp_path, "time,sensor,x,y\n1.2,1,0,0\n1.0,1,1,1\n3.0,1,2,2\n"))
    assert file_rows(t).tolist() == [1, 0, 2]
    plot = np.array([0, -1, 2, 1])
    assert plots_to_file_rows(plot, t).tolist() == [1, -1, 2, 0]
    assert plots_to_table_rows(plots_to_file_rows(plot, t), t).tolist() == plot.tolist()


def test_polar_site_given_by_position(tmp_path):
    """A polar radar placed by ``position`` converts from its site carried to the
    ellipsoid (``SensorSet.site_latlon``)."""
    s = SensorSet(ORIGIN, (RadarSensor(5, "polar", pd=0.9, position=(10_000.0, -5_000.0),
                                       sigma_range=50.0, sigma_bearing_deg=0.2),))
    t = read_plots(write(tmp_path, "time,sensor,range,bearing\n0,5,0.0,0.0\n"), sensors=s)
    assert np.allclose((t.x[0], t.y[0]), (10_000.0, -5_000.0), atol=1e-6)
