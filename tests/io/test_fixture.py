"""A small hand-written plots file read value by value, with a sensor registry; and the
TOML helpers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mhtrack.io import read_plots, read_toml, read_tracks, write_scenario_toml
from mhtrack.models.sensors import CartesianSensor, PolarRadar

# Scan 3 has no plot. Sensor 0 is Cartesian (range/bearing empty), sensor 4 a polar radar.
PLOTS = """\
scan,time,sensor,x,y,range,bearing,origin,comment
1,0.5,0,100.25,-200.5,,,2,extra columns are ignored
1,0.5,4,0,1000,1000,0,-1,due north of the radar
2,1.5,4,1000,0,1000,90,7,due east
4,3.5,0,-1e3,2.5e-3,,,-1,
"""


@pytest.fixture
def plots_csv(tmp_path: Path) -> Path:
    path = tmp_path / "plots.csv"
    path.write_text(PLOTS)
    return path


def test_fixture_values(plots_csv: Path) -> None:
    sigma_r, sigma_b = 20.0, 0.3
    registry = {0: CartesianSensor(0, sigma=50.0), 4: PolarRadar(4, (0.0, 0.0), sigma_r, sigma_b)}
    t = read_plots(plots_csv, sensors=registry)
    assert t.scan.tolist() == [1, 1, 2, 4]
    assert t.time.tolist() == [0.5, 0.5, 1.5, 3.5]
    assert t.sensor.tolist() == [0, 4, 4, 0]
    assert t.x.tolist() == [100.25, 0.0, 1000.0, -1000.0]  # from the file, not re-converted
    assert t.y.tolist() == [-200.5, 1000.0, 0.0, 0.0025]
    assert t.origin.tolist() == [2, -1, 7, -1]
    assert np.isnan(t.range[[0, 3]]).all() and np.isnan(t.bearing[[0, 3]]).all()
    assert t.range[1:3].tolist() == [1000.0, 1000.0]
    assert t.bearing[1:3].tolist() == [0.0, 90.0]
    assert t.scan.dtype == t.sensor.dtype == t.origin.dtype == np.int64
    # Cartesian rows: σ² I.
    np.testing.assert_array_equal(t.R[0], [[2500.0, 0.0], [0.0, 2500.0]])
    np.testing.assert_array_equal(t.R[3], [[2500.0, 0.0], [0.0, 2500.0]])
    # Polar rows, to first order: σr² along the line of sight, (r σθ)² across it.
    cross = (1000.0 * np.radians(sigma_b)) ** 2  # 27.4 m²
    north, east = t.R[1], t.R[2]
    np.testing.assert_allclose([north[1, 1], north[0, 0]], [sigma_r**2, cross], rtol=1e-3)
    np.testing.assert_allclose([east[0, 0], east[1, 1]], [sigma_r**2, cross], rtol=1e-3)
    assert abs(north[0, 1]) < 1e-9 * sigma_r**2 and abs(east[0, 1]) < 1e-9 * sigma_r**2
    # The empty scan 3 has no row; its time is interpolated.
    scans = list(t.scans())
    assert [(s.index, s.time, len(s)) for s in scans] == [
        (1, 0.5, 2),
        (2, 1.5, 1),
        (3, 2.5, 0),
        (4, 3.5, 1),
    ]
    assert scans[3].rows.tolist() == [3]


def test_fixture_without_registry_rejects_empty_range(plots_csv: Path) -> None:
    with pytest.raises(ValueError, match=r"plots\.csv, line 2, column 'range': value is missing"):
        read_plots(plots_csv)


def test_cartesian_registry_R_only_when_sigmas_differ(tmp_path: Path) -> None:
    path = tmp_path / "p.csv"
    path.write_text("scan,time,sensor,x,y\n1,0,0,1,2\n1,0,1,3,4\n")
    same = {0: CartesianSensor(0, sigma=10.0), 1: CartesianSensor(1, sigma=10.0)}
    assert read_plots(path, sensors=same).R is None
    assert read_plots(path).range is None
    differ = {0: CartesianSensor(0, sigma=10.0), 1: CartesianSensor(1, sigma=3.0)}
    R = read_plots(path, sensors=differ).R
    np.testing.assert_array_equal(R, [[[100.0, 0.0], [0.0, 100.0]], [[9.0, 0.0], [0.0, 9.0]]])


def test_tracks_fixture(tmp_path: Path) -> None:
    path = tmp_path / "tracks.csv"
    path.write_text(
        "scan,time,track_id,x,y,vx,vy,plot,score\n"
        "2,1.5,10,1,2,3,4,2,7.5\n"
        "3,2.5,10,4,6,3,4,,6.25\n"
        "4,3.5,10,7,10,3,4,3,9\n"
    )
    t = read_tracks(path)
    assert t.plot.tolist() == [2, -1, 3]
    assert t.score.tolist() == [7.5, 6.25, 9.0]
    assert t.track_id.tolist() == [10, 10, 10]
    assert t.positions.tolist() == [[1, 2], [4, 6], [7, 10]]
    assert t.vx.tolist() == [3.0, 3.0, 3.0]


def test_toml_round_trip_is_exact(tmp_path: Path) -> None:
    data = {
        "name": "crossing",
        "seed": np.int64(7),
        "T": 0.1,
        "region": {"xmin": -4000.0, "xmax": np.float64(1 / 3)},
        "scans": (1, 90),
        "sensors": [{"id": 0, "sigma": 100.0, "position": np.array([1e-300, -2.5])}],
        "flag": True,
    }
    path = tmp_path / "scenario.toml"
    write_scenario_toml(data, path)
    back = read_toml(path)
    assert back == {
        "name": "crossing",
        "seed": 7,
        "T": 0.1,
        "region": {"xmin": -4000.0, "xmax": 1 / 3},
        "scans": [1, 90],
        "sensors": [{"id": 0, "sigma": 100.0, "position": [1e-300, -2.5]}],
        "flag": True,
    }
    assert type(back["seed"]) is int
