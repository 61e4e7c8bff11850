"""The clutter map and the forgetting mixture inside the MHT: by name, per radar on timed
plots, saved and loaded with the tracker, and the map driving the birth density."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from tests.helpers.npz_members import members, write_members

from mhtrack.build import load_tracker, make_clutter_estimator, make_tracker
from mhtrack.cli.clutter_commands import clutter as clutter_command
from mhtrack.clutter.forgetting import ForgettingGMMClutter
from mhtrack.clutter.per_sensor import PerSensorClutter
from mhtrack.clutter.radar_map import ClutterMap, map_snapshots
from mhtrack.errors import InputError
from mhtrack.mht.births.clutter_scaled import ClutterScaledBirth
from mhtrack.models.radars import RadarSensor, SensorSet
from mhtrack.records import Scan
from mhtrack.scenario import preset, simulate


def test_by_name() -> None:
    assert isinstance(make_tracker("mht-map").clutter, ClutterMap)
    assert isinstance(make_tracker("mht-fgmm").clutter, ForgettingGMMClutter)
    m = make_clutter_estimator("map", site=(100.0, -50.0), range_cell=250.0)
    assert m.site == (100.0, -50.0) and m.range_cell == 250.0
    with pytest.raises(TypeError):
        make_clutter_estimator("map", window=5)


def _sensors() -> SensorSet:
    return SensorSet(None, (
        RadarSensor(1, "polar", lat=51.0, lon=0.0, sigma_range=50.0, sigma_bearing_deg=0.1,
                    pd=0.9, period=4.0, max_range=60e3),
        RadarSensor(2, "polar", lat=51.5, lon=0.5, sigma_range=50.0, sigma_bearing_deg=0.1,
                    pd=0.9, period=6.0)))


def _frame(k: int, sensor: int, z: np.ndarray, t: float) -> Scan:
    n = len(z)
    return Scan(k, t, np.asarray(z, float).reshape(-1, 2), np.full(n, sensor),
                np.arange(n) + 1000 * k, t=np.full(n, t))


def test_timed_path_one_map_per_radar_about_its_site_a_rotation_at_a_time() -> None:
    sensors = _sensors()
    trk = make_tracker("mht-map", sensors=sensors, clutter_params={"range_cell": 1000.0})
    est = trk.clutter
    assert isinstance(est, PerSensorClutter)
    for sid in (1, 2):
        m = est.estimator(sid)
        assert isinstance(m, ClutterMap) and m.range_cell == 1000.0
        assert m.site == pytest.approx(sensors.site_xy(sid))
    assert est.estimator(1).n_rings == 60  # out to its max_range, 60 km
    site = np.asarray(sensors.site_xy(1))
    near = site + np.array([[0.0, 500.0]] * 3)  # ring 0, sector 0 of radar 1
    est.update(_frame(0, 1, near[:2], 0.5))
    est.update(_frame(1, 1, near[2:], 2.0))
    assert not est.has_estimate(1)  # the rotation is not complete
    est.update(_frame(2, 1, near[:1] + 10_000.0, 4.6))  # next rotation: the first is fed
    m = est.estimator(1)
    assert m.sums_[0, 0] == 3.0 and m.looks_ == 1.0
    snaps = map_snapshots(est, 4.6)
    assert list(snaps) == [1] and snaps[1].site == m.site


def test_save_and_load_continue_identically(tmp_path: Path) -> None:
    sim = simulate(preset("crossing", scans=10), seed=3)
    scans = list(sim.plots.scans())
    for name, params in (("mht-map", {"birth_scaling": 1.0, "range_cell": 400.0}),
                         ("mht-fgmm", None)):
        trk = make_tracker(name, clutter_params=params)
        for s in scans[:6]:
            trk.step(s)
        path = trk.save(tmp_path / f"{name}.npz") or tmp_path / f"{name}.npz"
        back = load_tracker(path)
        assert type(back.birth) is type(trk.birth)
        for s in scans[6:]:
            a, b = trk.step(s), back.step(s)
            np.testing.assert_array_equal(a.positions, b.positions)
            np.testing.assert_array_equal(trk.last_kappa, back.last_kappa)


def test_a_damaged_map_state_is_refused_naming_the_member(tmp_path: Path) -> None:
    sim = simulate(preset("crossing", scans=4), seed=3)
    trk = make_tracker("mht-map")
    for s in sim.plots.scans():
        trk.step(s)
    path = tmp_path / "s.npz"
    trk.save(path)
    arrays = members(path)
    key = next(k for k, v in arrays.items() if k.startswith("clutter__") and v.ndim == 2)
    arrays[key] = -arrays[key] - 1.0
    write_members(path, arrays)
    with pytest.raises(InputError, match=r"clutter_state.*negative"):
        load_tracker(path)


def test_the_map_scales_the_birth_density_where_clutter_is_dense() -> None:
    """Birth scores with ``birth_scaling`` β = 1 are ``ln(s λ_v P_D / (κ̂ + s λ_v))`` with
    ``s = min(1, ρ̄/κ̂)`` (computed here from the map's own numbers): lower than without
    where the map is denser than its mean, the same elsewhere."""
    sim = simulate(preset("crossing", scans=12), seed=1)
    scans = list(sim.plots.scans())
    trk = make_tracker("mht-map", clutter_params={"birth_scaling": 1.0})
    assert isinstance(trk.birth, ClutterScaledBirth)
    for s in scans[:11]:
        trk.step(s)
    f = trk._frame(scans[11])
    trk.clutter.update(scans[11])
    kappa = trk.clutter.intensity(f.z)
    cand = trk.birth.propose(f, kappa, None)
    plain = trk.birth.inner.propose(f, kappa, None)
    cfg = trk.config
    rho = trk.clutter.mean_intensity()
    row = {int(r): i for i, r in enumerate(f.rows)}
    idx = np.array([row[int(r)] for r in cand.window[:, -1]])
    s = np.minimum(1.0, rho / kappa[idx])
    lam = cfg.new_target_density * s
    expect = np.log(lam * cfg.p_detection) - np.log(kappa[idx] + lam)
    np.testing.assert_allclose(cand.score, expect, rtol=1e-12)
    dense = kappa > rho
    assert dense.any()  # plots lie where clutter is: most above the map-wide mean
    assert len(cand) <= len(plain)
    kept = {int(r): sc for r, sc in zip(cand.window[:, -1], cand.score, strict=True)}
    for r, sc in zip(plain.window[:, -1], plain.score, strict=True):
        i = row[int(r)]
        if int(r) in kept:
            assert kept[int(r)] < sc if dense[i] else kept[int(r)] == pytest.approx(sc)
    assert math.isfinite(rho) and rho > 0


def test_cli_draws_the_map_over_time(tmp_path: Path) -> None:
    res = CliRunner().invoke(clutter_command, [
        "crossing-changing", "--estimator", "map", "--scans", "8", "--resolution", "50",
        "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "clutter_maps.png").stat().st_size > 10_000
