"""Tracks and truth files written with a local frame: lat, lon and east/north velocities
checked against GeographicLib; read back to exactly the local-frame tables."""

from __future__ import annotations

import numpy as np
import pyarrow.csv as pacsv
import pytest
from geodesic_reference import WGS84

from mhtrack.errors import InputError
from mhtrack.io import read_tracks, read_truth, write_tracks, write_truth
from mhtrack.io.plots import read_plots
from mhtrack.metrics import evaluate
from mhtrack.models.geodesy import LocalFrame
from mhtrack.records import TrackTable, TruthTable

FRAME = LocalFrame(46.8, 8.2)


def tables() -> tuple[TruthTable, TrackTable]:
    rng = np.random.default_rng(7)
    n = 12
    scan = np.repeat(np.arange(6), 2)
    time = scan * 4.0
    ids = np.tile([0, 1], 6)
    x = rng.uniform(-200e3, 200e3, n)
    y = rng.uniform(-200e3, 200e3, n)
    vx, vy = rng.uniform(-250, 250, n), rng.uniform(-250, 250, n)
    truth = TruthTable(scan, time, ids, x, y, vx, vy)
    tracks = TrackTable(scan, time, ids + 10, x + rng.normal(0, 90, n),
                        y + rng.normal(0, 90, n), vx + 3, vy - 2,
                        np.where(ids == 0, np.arange(n), -1), score=rng.normal(size=n))
    return truth, tracks


def enu_by_geographiclib(lat: float, lon: float, x: float, y: float, vx: float, vy: float
                         ) -> tuple[float, float]:
    """East/north velocity at a point whose grid velocity is (vx, vy): move 1 s along the
    grid, find the geodesic from the point to where that lands (GeographicLib inverse)."""
    lat2, lon2 = FRAME.to_geodetic(x + vx * 1e-3, y + vy * 1e-3)
    g = WGS84.Inverse(lat, lon, float(lat2), float(lon2))
    a = np.radians(g["azi1"])
    return g["s12"] * np.sin(a) * 1e3, g["s12"] * np.cos(a) * 1e3


@pytest.mark.parametrize("fmt", ["csv", "parquet"])
def test_geodetic_columns_and_exact_read_back(tmp_path, fmt):
    truth, tracks = tables()
    write_truth(truth, tmp_path / f"g.{fmt}", FRAME)
    write_tracks(tracks, tmp_path / f"t.{fmt}", FRAME)
    g, t = read_truth(tmp_path / f"g.{fmt}"), read_tracks(tmp_path / f"t.{fmt}")
    for a, b in ((g, truth), (t, tracks)):
        for c in ("scan", "time", "x", "y", "vx", "vy"):
            assert np.array_equal(getattr(a, c), getattr(b, c)), c
    ev_mem = evaluate(tracks, truth).to_dict()
    ev_file = evaluate(t, g).to_dict()
    assert ev_mem == ev_file


def test_lat_lon_and_east_north_match_geographiclib(tmp_path):
    truth, _ = tables()
    write_truth(truth, tmp_path / "g.csv", FRAME)
    f = pacsv.read_csv(tmp_path / "g.csv").to_pydict()
    assert list(f) == ["scan", "time", "target_id", "x", "y", "lat", "lon", "vx", "vy",
                       "vx_grid", "vy_grid"]
    for i in range(len(truth)):
        g = WGS84.Direct(46.8, 8.2, np.degrees(np.arctan2(truth.x[i], truth.y[i])),
                                  np.hypot(truth.x[i], truth.y[i]))
        assert f["lat"][i] == pytest.approx(g["lat2"], abs=1e-9)
        assert f["lon"][i] == pytest.approx(g["lon2"], abs=1e-9)
        ve, vn = enu_by_geographiclib(f["lat"][i], f["lon"][i], truth.x[i], truth.y[i],
                                      truth.vx[i], truth.vy[i])
        assert (f["vx"][i], f["vy"][i]) == pytest.approx((ve, vn), abs=1e-3)


def test_lat_lon_only_files_need_the_frame(tmp_path):
    """A user's truth in lat, lon, east/north velocities (no local columns)."""
    truth, _ = tables()
    write_truth(truth, tmp_path / "full.csv", FRAME)
    full = pacsv.read_csv(tmp_path / "full.csv")
    user = full.select(["scan", "time", "target_id", "lat", "lon", "vx", "vy"])
    pacsv.write_csv(user, tmp_path / "user.csv")
    with pytest.raises(InputError, match=r"user.csv: has lat, lon \(so vx, vy are "
                       r"east/north\) but no x, y and vx_grid, vy_grid: read it with the "
                       r"sensors file"):
        read_truth(tmp_path / "user.csv")
    g = read_truth(tmp_path / "user.csv", frame=FRAME)
    assert np.allclose(g.x, truth.x, atol=1e-6) and np.allclose(g.y, truth.y, atol=1e-6)
    assert np.allclose(g.vx, truth.vx, atol=1e-9) and np.allclose(g.vy, truth.vy, atol=1e-9)


def test_latitude_out_of_range_is_located(tmp_path):
    p = tmp_path / "g.csv"
    p.write_text("scan,time,target_id,x,y,lat,lon,vx,vy,vx_grid,vy_grid\n"
                 "0,0,1,0,0,46.8,8.2,1,1,1,1\n1,1,1,0,0,95,8.2,1,1,1,1\n")
    with pytest.raises(InputError) as e:
        read_truth(p)
    assert str(e.value) == (f"{p}, line 3, column 'lat': latitude 95.0 is outside [-90, 90] "
                            "degrees")


def test_tracks_plot_column_names_the_file_row(tmp_path):
    plots = tmp_path / "p.csv"
    plots.write_text("time,sensor,x,y\n2.0,1,5,5\n1.0,1,1,1\n3.0,1,9,9\n")
    table = read_plots(plots)  # table rows: 1.0 (file row 1), 2.0 (file row 0), 3.0
    tr = TrackTable(np.array([0, 0]), np.array([3.0, 3.0]), np.array([4, 5]),
                    np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(2), np.array([0, -1]))
    write_tracks(tr, tmp_path / "t.csv", plots=table)
    assert read_tracks(tmp_path / "t.csv").plot.tolist() == [1, -1]
    assert read_tracks(tmp_path / "t.csv", plots=table).plot.tolist() == [0, -1]
