"""Per-plot-type errors and P_D in the sensors file (issue 29 item 2): the tables read and
write back, bad ones are one located InputError each (checked verbatim), a plot's σ is
its type's where the file gives one (checked against the conversion with that type's
scalars, the former code path), its update term uses its type's P_D (hand-worked), and a
file without type tables gives the very floats of today."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mhtrack.attributes import COMBINED, MODE_S, PRIMARY, SECONDARY, PlotAttributes
from mhtrack.errors import InputError
from mhtrack.io.sensors import read_sensors, write_sensors
from mhtrack.io.timed_plots import polar_plots, read_timed_plots
from mhtrack.mht.coverage import RadarCoverage
from mhtrack.mht.scoring import update_increment
from mhtrack.models.geodesy import polar_to_local
from mhtrack.records import Scan

BASE = """\
[origin]
lat = 50.0
lon = 8.0
[[sensors]]
id = 1
kind = "polar"
lat = 50.0
lon = 8.0
pd = 0.9
sigma_range = 100.0
sigma_bearing_deg = 0.1
"""
TYPES = BASE + """\
mode_s = { sigma_range = 30.0, pd = 0.99 }
[sensors.primary]
sigma_range = 120.0
sigma_bearing_deg = 0.15
pd = 0.8
"""


def _write(tmp_path, text: str, name: str = "sensors.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_tables_read_and_write_back(tmp_path):
    s = read_sensors(_write(tmp_path, TYPES))
    r = s.sensors[0]
    assert set(r.plot_types) == {("primary", 0.8, 120.0, 0.15), ("mode_s", 0.99, 30.0, None)}
    write_sensors(s, tmp_path / "back.toml")
    assert read_sensors(tmp_path / "back.toml") == s
    types = np.array([0, PRIMARY, SECONDARY, COMBINED, MODE_S])
    sr, sb = r.sigmas(types)
    np.testing.assert_array_equal(sr, [100.0, 120.0, 100.0, 100.0, 30.0])
    np.testing.assert_array_equal(sb, [0.1, 0.15, 0.1, 0.1, 0.1])
    np.testing.assert_array_equal(r.pds(types), [0.9, 0.8, 0.9, 0.9, 0.99])
    assert r.sigmas(None) == (100.0, 0.1) and r.pds(None) == 0.9


@pytest.mark.parametrize("extra, line, message", [
    ("[sensors.primary]\npd = 1.5\n", 13, "key 'sensors[0].primary.pd': must be in (0, 1], "
     "got 1.5"),
    ("[sensors.primary]\npdd = 0.5\n", 13, "key 'sensors[0].primary.pdd': unknown key; did "
     "you mean 'pd'?"),
    ("mode_s = { sigma_range = -3.0 }\n", 12, "key 'sensors[0].mode_s.sigma_range': must be "
     "in [1e-09, 1e6] m, got -3"),
    ("secondary = 0.9\n", 12, "key 'sensors[0].secondary': expected a table, got float 0.9"),
    ("[sensors.combined]\nsigma_bearing_deg = 'wide'\n", 13,
     "key 'sensors[0].combined.sigma_bearing_deg': expected a number, got string 'wide'"),
])
def test_bad_tables_are_located(tmp_path, extra, line, message):
    path = _write(tmp_path, BASE + extra)
    with pytest.raises(InputError) as e:
        read_sensors(path)
    assert str(e.value) == f"{path}, line {line}, {message}"


def test_type_table_on_a_cartesian_sensor_is_refused(tmp_path):
    text = "[[sensors]]\nid = 2\nkind = \"cartesian\"\nsigma = 50.0\npd = 0.9\n" \
           "[sensors.mode_s]\npd = 0.99\n"
    path = _write(tmp_path, text)
    with pytest.raises(InputError) as e:
        read_sensors(path)
    assert str(e.value) == (f"{path}, line 6, key 'sensors[0].mode_s': per-plot-type errors "
                            "and P_D apply to a polar radar's plots, not to a cartesian "
                            "sensor")


def test_each_plot_converted_with_its_types_sigma(tmp_path):
    s = read_sensors(_write(tmp_path, TYPES))
    rng = np.array([20e3, 60e3, 90e3, 150e3, 45e3])
    brg = np.array([10.0, 100.0, 200.0, 300.0, 359.0])
    types = np.array([PRIMARY, MODE_S, SECONDARY, PRIMARY, 0])
    x, y, R = polar_plots(s, 1, rng, brg, types)
    frame, site = s.frame(), s.site_latlon(1)
    for code, sr, sb in ((PRIMARY, 120.0, 0.15), (MODE_S, 30.0, 0.1), (SECONDARY, 100.0, 0.1),
                         (0, 100.0, 0.1)):
        k = types == code
        z, R0 = polar_to_local(frame, *site, rng[k], brg[k], sr, sb)
        np.testing.assert_allclose(R[k], R0, rtol=1e-12)
        np.testing.assert_array_equal(np.column_stack((x[k], y[k])), z)
    # without type tables: the same floats as the former scalar call
    plain = read_sensors(_write(tmp_path, BASE, "plain.toml"))
    x1, y1, R1 = polar_plots(plain, 1, rng, brg, types)
    z, R0 = polar_to_local(plain.frame(), *plain.site_latlon(1), rng, brg, 100.0, 0.1)
    np.testing.assert_array_equal(R1, R0)
    np.testing.assert_array_equal(np.column_stack((x1, y1)), z)


def test_timed_plots_file_uses_the_plot_types(tmp_path):
    sensors = _write(tmp_path, TYPES)
    plots = tmp_path / "plots.csv"
    plots.write_text("time,sensor,range,bearing,plot_type\n0.0,1,50000,30,primary\n"
                     "0.5,1,50000,90,mode_s\n1.0,1,50000,150,secondary\n")
    t = read_timed_plots(plots, read_sensors(sensors))
    s = read_sensors(sensors)
    for row, (sr, sb) in enumerate(((120.0, 0.15), (30.0, 0.1), (100.0, 0.1))):
        i = int(np.flatnonzero(t.file_row == row)[0])
        _, R0 = polar_to_local(s.frame(), *s.site_latlon(1), [50000.0],
                               [30.0 + 60.0 * row], sr, sb)
        np.testing.assert_allclose(t.R[i], R0[0], rtol=1e-12)


def _scan(types: list[int] | None) -> Scan:
    n = 3
    attrs = None if types is None else PlotAttributes.from_columns(
        {"plot_type": np.array(types)}, n)
    return Scan(index=0, time=1.0, z=np.zeros((n, 2)), sensor=np.ones(n, np.int64),
                rows=np.arange(n), attrs=attrs)


def test_update_term_uses_the_plots_type_pd(tmp_path):
    cov = RadarCoverage(read_sensors(_write(tmp_path, TYPES)), max_pd=0.995)
    pds = cov.plot_pds(_scan([PRIMARY, MODE_S, COMBINED]))
    np.testing.assert_array_equal(pds, [0.8, 0.99, 0.9])
    assert cov.plot_pds(_scan(None)) == cov.plot_pd(_scan(None)) == 0.9
    loglik = np.array([-10.0, -12.0, -11.0, -9.5])
    kappa = np.array([1e-9, 2e-9, 3e-9])
    plot = np.array([0, 1, 2, 1])
    lam = 2e-11
    got = update_increment(loglik, kappa, pds, lam, plot)
    want = [loglik[i] + math.log([0.8, 0.99, 0.9][p]) - math.log(kappa[p] + lam)
            for i, p in enumerate(plot)]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    capped = RadarCoverage(read_sensors(_write(tmp_path, TYPES, "c.toml")), max_pd=0.95)
    np.testing.assert_array_equal(capped.plot_pds(_scan([MODE_S, PRIMARY, 0])),
                                  [0.95, 0.8, 0.9])


def test_without_type_tables_the_update_term_is_todays(tmp_path):
    cov = RadarCoverage(read_sensors(_write(tmp_path, BASE)))
    pd = cov.plot_pds(_scan([PRIMARY, MODE_S, COMBINED]))
    assert isinstance(pd, float) and pd == 0.9
    loglik, kappa = np.array([-10.0, -12.0]), np.array([1e-9, 2e-9])
    a = update_increment(loglik, kappa, pd, 2e-11, np.array([0, 1]))
    per = math.log(0.9) - np.log(kappa + 2e-11)
    np.testing.assert_array_equal(a, loglik + per)
