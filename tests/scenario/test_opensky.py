"""OpenSky truth: geodetic conversion by hand, counts and velocities against the raw CSV."""

import csv
import io
import math
from collections import Counter
from importlib import resources

import numpy as np
import pytest

from mhtrack.scenario import aircraft_ids, geodetic_to_enu, load_opensky, preset, simulate
from mhtrack.scenario.geodesy import local_to_reference_velocity
from mhtrack.scenario.opensky import REFERENCE


def _csv_rows():
    text = resources.files("mhtrack").joinpath("data", "opensky_plane_states.csv").read_text()
    return list(csv.DictReader(io.StringIO(text)))


def test_enu_of_reference_is_origin():
    assert np.allclose(geodetic_to_enu(*REFERENCE, *REFERENCE), 0.0, atol=1e-6)


def test_enu_one_degree_north_hand_worked():
    # ρ = N cos φ, z = N (1 − e²) sin φ in the meridian plane, N = a / sqrt(1 − e² sin²φ);
    # north = −sin φ0 (ρ1 − ρ0) + cos φ0 (z1 − z0), up = cos φ0 (ρ1 − ρ0) + sin φ0 (z1 − z0).
    # φ0 = 52.067°, φ1 = 53.067°: N0 = 6 391 314.7 m, N1 = 6 391 547.5 m →
    # north = 111 272.44 m (1° of latitude ≈ 111.2 km), up = −971.09 m (earth curvature).
    lat0, lon0 = REFERENCE
    e, n, u = geodetic_to_enu(lat0 + 1.0, lon0, lat0, lon0)
    assert abs(e) < 1e-6
    assert n == pytest.approx(111_272.443, abs=0.01)
    assert u == pytest.approx(-971.087, abs=0.01)
    assert n == pytest.approx(111_200, abs=200)


def test_enu_one_degree_east_closed_form():
    # same latitude: east = N(φ0) cos φ0 sin Δλ (the ECEF difference lies in the parallel)
    lat0, lon0 = REFERENCE
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    phi = math.radians(lat0)
    big_n = a / math.sqrt(1 - e2 * math.sin(phi) ** 2)
    east = big_n * math.cos(phi) * math.sin(math.radians(1.0))
    assert geodetic_to_enu(lat0, lon0 + 1.0, lat0, lon0)[0] == pytest.approx(east, abs=1e-6)
    assert east == pytest.approx(68_571.96, abs=0.01)


def test_counts_per_scan_match_the_csv():
    rows = _csv_rows()
    per_time = Counter(int(r["time"]) for r in rows)
    t0 = min(per_time)
    expect = {(t - t0) // 10: n for t, n in per_time.items()}
    d = load_opensky()
    got = Counter(d.scan.tolist())
    assert got == expect
    assert sorted(got) == list(range(121))
    assert max(got.values()) == 57 and min(got[k] for k in range(1, 121)) == 44
    assert len(set(d.target_id.tolist())) == 84
    # truth of the simulated preset: same per-scan counts
    sim = simulate(preset("opensky"), 0)
    assert Counter(sim.truth.scan.tolist()) == expect
    assert np.array_equal(sim.truth.time, sim.truth.scan * 10.0)


def test_ids_in_order_of_first_appearance():
    rows = _csv_rows()
    first_seen = list(dict.fromkeys(r["icao24"] for r in rows))
    ids = aircraft_ids()
    assert list(ids) == list(range(1, 85))
    assert list(ids.values()) == first_seen
    assert ids[1] == "3c4591"
    d = load_opensky()
    assert d.target_id[d.scan == 0].tolist() == [1]


def test_positions_span_hundreds_of_km():
    d = load_opensky()
    assert np.ptp(d.x) > 400e3 and np.ptp(d.y) > 400e3
    assert np.ptp(d.x) < 600e3 and np.ptp(d.y) < 600e3  # southern England, not the globe


def test_velocity_columns_are_east_and_north():
    """x_speed / y_speed against position differences of fresh consecutive reports."""
    d = load_opensky()
    rows = _csv_rows()
    icao = np.array([r["icao24"] for r in rows])
    lat, lon, t, lp, vx, vy = (
        np.array([float(r[k]) for r in rows])
        for k in ("lat", "lon", "time", "lastposupdate", "x_speed", "y_speed")
    )
    enu = geodetic_to_enu(lat, lon, *REFERENCE)[:, :2]
    v = local_to_reference_velocity(vx, vy, lat, lon, *REFERENCE)
    order = np.lexsort((t, icao))
    a, b = order[:-1], order[1:]
    ok = (icao[a] == icao[b]) & (t[b] - t[a] == 10) & (t[a] - lp[a] < 1) & (t[b] - lp[b] < 1)
    ok &= lp[b] - lp[a] > 5
    a, b = a[ok], b[ok]
    assert len(a) > 2000
    fd = (enu[b] - enu[a]) / (lp[b] - lp[a])[:, None]
    vm = 0.5 * (v[a] + v[b])
    err = np.linalg.norm(fd - vm, axis=1)
    assert np.median(err) < 2.0  # m/s, aircraft fly at ~100–250 m/s
    swapped = np.linalg.norm(fd - vm[:, ::-1], axis=1)
    assert np.median(swapped) > 50.0
    # the rotation into the reference frame matters: raw local components fit worse
    raw = np.column_stack((0.5 * (vx[a] + vx[b]), 0.5 * (vy[a] + vy[b])))
    assert np.median(np.linalg.norm(fd - raw, axis=1)) > np.median(err)
    # the loaded truth (positions dead-reckoned to the grid) agrees with its velocities
    o = np.lexsort((d.scan, d.target_id))
    a, b = o[:-1], o[1:]
    ok = (d.target_id[a] == d.target_id[b]) & (d.scan[b] - d.scan[a] == 1)
    ok &= (d.age[a] < 1) & (d.age[b] < 1)
    fd = np.column_stack((d.x[b] - d.x[a], d.y[b] - d.y[a])) / 10.0
    vm = 0.5 * np.column_stack((d.vx[a] + d.vx[b], d.vy[a] + d.vy[b]))
    assert np.median(np.linalg.norm((fd - vm)[ok], axis=1)) < 2.0


def test_positions_dead_reckoned_to_grid_time_and_stale_rows_droppable():
    d = load_opensky()
    i = int(np.argmax(d.age))
    raw = geodetic_to_enu(d.lat[i], d.lon[i], *REFERENCE)[:2]
    assert np.allclose([d.x[i], d.y[i]], raw + d.age[i] * np.array([d.vx[i], d.vy[i]]))
    fresh = load_opensky(max_position_age=30.0)
    assert len(fresh) < len(d) and fresh.age.max() <= 30.0
    with pytest.raises(ValueError, match="max_position_age"):
        load_opensky(max_position_age=-1.0)


def test_opensky_simulation_uses_two_polar_radars():
    sim = simulate(preset("opensky", scans=5), 1)
    p = sim.plots
    assert sorted(set(p.sensor.tolist())) == [1, 2]
    assert np.array_equal(p.time, p.scan * 10.0)  # t = k·T
    assert np.isfinite(p.range).all() and p.R.shape == (len(p), 2, 2)
    det = (p.origin >= 0).sum()
    n = 2 * len(sim.truth)
    assert abs(det - 0.9 * n) < 4 * np.sqrt(n * 0.09)
