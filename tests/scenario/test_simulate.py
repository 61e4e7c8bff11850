"""Plots of simulated scenarios against independent facts: Poisson clutter counts at the
scenario's rate, binomial detections, the closed-form CV motion, polar noise against σr/σθ,
clutter positions against their model, determinism, and the polar columns."""

import dataclasses
import hashlib
import os
import subprocess
import sys

import numpy as np
import pytest
from scipy import stats

from mhtrack.models.clutter import UniformClutter
from mhtrack.models.sensors import CartesianSensor, PolarRadar
from mhtrack.scenario import preset, simulate


@pytest.fixture(scope="module")
def crossing_sim():
    return simulate(preset("crossing"), seed=1)


def test_crossing_counts(crossing_sim):
    sc = preset("crossing")
    p, truth = crossing_sim.plots, crossing_sim.truth
    assert p.n_scans == sc.n_scans
    assert np.array_equal(p.scan_times[0], sc.scan_indices())
    assert np.array_equal(p.scan_times[1], sc.scan_indices() * sc.T)  # t = k·T
    clutter = p.origin == -1
    # live target-scans in closed form: scans birth..death clipped to the scenario's range
    n_live = sum(min(t.death, sc.last) - max(t.birth, sc.first) + 1 for t in sc.targets)
    assert len(truth) == n_live
    # each live target detected with P_D: binomial bound (4 sd)
    pd = sc.pd[0]
    det = (~clutter).sum()
    assert abs(det - pd * n_live) < 4 * np.sqrt(n_live * pd * (1 - pd))
    # target plots only from live targets, at most one per target per scan
    live = set(zip(truth.scan.tolist(), truth.target_id.tolist(), strict=True))
    pairs = list(zip(p.scan[~clutter].tolist(), p.origin[~clutter].tolist(), strict=True))
    assert set(pairs) <= live and len(set(pairs)) == len(pairs)
    # no plot of a target after its death scan
    for t in sc.targets:
        assert not np.any((p.origin == t.id) & (p.scan > t.death))
    assert np.all(np.diff(p.scan) >= 0)
    assert p.R is None and p.range is None  # one Cartesian sensor: tracker's own R


@pytest.mark.parametrize("name", ["crossing", "multiradar"])
def test_clutter_counts_are_poisson_with_the_scenario_rate(name):
    """Per scan and sensor the clutter count is Poisson(λ_k), λ_k = the scenario's rate:
    over 5 fixed seeds the mean count is within 4 standard errors of λ and the dispersion
    statistic (N−1)·s²/λ lies inside the χ²(N−1) 1e-4 … 1 − 1e-4 quantiles."""
    sc = preset(name, scans=40)
    lam = np.array([sc.clutter_rate(k) for k in sc.scan_indices()])
    assert np.ptp(lam) == 0  # these presets have a constant rate
    counts = []
    for seed in range(5):
        p = simulate(sc, seed).plots
        for s in sc.sensors:
            c = (p.origin == -1) & (p.sensor == s.id)
            counts.append(np.bincount(p.scan[c] - sc.first, minlength=sc.n_scans))
    n = np.concatenate(counts).astype(float)
    assert abs(n.mean() - lam[0]) < 4 * np.sqrt(lam[0] / n.size)
    dispersion = (n.size - 1) * n.var(ddof=1) / lam[0]
    lo, hi = stats.chi2.ppf([1e-4, 1 - 1e-4], n.size - 1)
    assert lo < dispersion < hi


def test_truth_follows_the_closed_form_constant_velocity_motion():
    """Without truth noise, target ``i`` at scan ``k`` is at ``(x0 + vx·(k − birth)·T,
    y0 + vy·(k − birth)·T)`` with velocity ``(vx, vy)``: P1 §1.1's CV model, solved by hand."""
    for name in ("crossing", "multiradar"):
        sc = preset(name)
        assert sc.truth_sigma_v == 0.0
        truth = simulate(sc, 3).truth
        for t in sc.targets:
            m = truth.target_id == t.id
            x0, vx, y0, vy = t.state
            dt = (truth.scan[m] - t.birth) * sc.T
            assert np.allclose(truth.x[m], x0 + vx * dt, rtol=0, atol=1e-6)
            assert np.allclose(truth.y[m], y0 + vy * dt, rtol=0, atol=1e-6)
            assert np.all(truth.vx[m] == vx) and np.all(truth.vy[m] == vy)


def test_polar_plot_noise_matches_sigma_range_and_bearing():
    """Target plots of a polar radar: range and bearing errors against the truth are
    zero-mean with standard deviations σr and σθ (4 standard errors, over 3 seeds)."""
    sc = preset("multiradar", clutter_rate=0.0)
    dr: dict[int, list[np.ndarray]] = {s.id: [] for s in sc.sensors}
    db: dict[int, list[np.ndarray]] = {s.id: [] for s in sc.sensors}
    for seed in range(3):
        sim = simulate(sc, seed)
        p, truth = sim.plots, sim.truth
        row = {(k, i): j for j, (k, i) in enumerate(zip(truth.scan.tolist(),
                                                         truth.target_id.tolist(), strict=True))}
        for s in sc.sensors:
            m = np.flatnonzero((p.sensor == s.id) & (p.origin >= 0))
            rows = [row[(k, i)] for k, i in zip(p.scan[m].tolist(), p.origin[m].tolist(),
                                                 strict=True)]
            d = truth.positions[rows] - np.asarray(s.position)
            true_range = np.hypot(d[:, 0], d[:, 1])
            true_bearing = np.degrees(np.arctan2(d[:, 0], d[:, 1]))  # clockwise from north
            dr[s.id].append(p.range[m] - true_range)
            db[s.id].append((p.bearing[m] - true_bearing + 180.0) % 360.0 - 180.0)
    for s in sc.sensors:
        r, b = np.concatenate(dr[s.id]), np.concatenate(db[s.id])
        n = r.size
        assert abs(r.mean()) < 4 * s.sigma_range / np.sqrt(n)
        assert abs(b.mean()) < 4 * s.sigma_bearing_deg / np.sqrt(n)
        assert r.std() == pytest.approx(s.sigma_range, rel=4 / np.sqrt(2 * n))
        assert b.std() == pytest.approx(s.sigma_bearing_deg, rel=4 / np.sqrt(2 * n))


def test_target_plot_errors_match_sensor_sigma(crossing_sim):
    p, truth = crossing_sim.plots, crossing_sim.truth
    tgt = np.flatnonzero(p.origin >= 0)
    key = {
        (k, i): j
        for j, (k, i) in enumerate(zip(truth.scan.tolist(), truth.target_id.tolist(), strict=True))
    }
    rows = np.array([key[(p.scan[j], p.origin[j])] for j in tgt])
    err = p.z[tgt] - truth.positions[rows]
    n = err.size
    assert err.std() == pytest.approx(100.0, rel=4 / np.sqrt(2 * n) + 0.01)


def test_plot_order_within_scan_leaks_no_origin(crossing_sim):
    p = crossing_sim.plots
    ranks = []
    for k in range(1, 91):
        idx = np.flatnonzero(p.scan == k)
        pos = np.flatnonzero(p.origin[idx] >= 0)
        ranks.extend((pos / (len(idx) - 1)).tolist())
    # relative position of target plots in their scan ~ U[0, 1]: mean 1/2, sd 1/sqrt(12)
    assert abs(np.mean(ranks) - 0.5) < 4 / np.sqrt(12 * len(ranks))


def _digest(sim) -> str:
    h = hashlib.sha256()
    p = sim.plots
    for a in (
        p.scan,
        p.time,
        p.sensor,
        p.x,
        p.y,
        p.range,
        p.bearing,
        p.origin,
        p.R,
        sim.truth.x,
        sim.truth.y,
    ):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def test_same_seed_identical_different_seed_differs():
    s = preset("multiradar", truth_sigma_v=2.0)
    a, b, c = simulate(s, 7), simulate(s, 7), simulate(s, 8)
    for name in ("scan", "time", "sensor", "x", "y", "range", "bearing", "origin", "R"):
        assert getattr(a.plots, name).tobytes() == getattr(b.plots, name).tobytes()
    assert a.truth.x.tobytes() == b.truth.x.tobytes()
    assert _digest(a) == _digest(b) != _digest(c)
    assert not np.array_equal(a.truth.x, c.truth.x)  # truth noise follows the seed too


def test_output_independent_of_python_hash_seed():
    code = (
        "import hashlib, numpy as np\n"
        "from mhtrack.scenario import preset, simulate\n"
        "s = simulate(preset('multiradar', scans=3, truth_sigma_v=1.0), 5)\n"
        "print(hashlib.sha256(s.plots.x.tobytes() + s.plots.origin.tobytes()).hexdigest())\n"
    )
    out = set()
    for hs in ("0", "4242"):
        env = {**os.environ, "PYTHONHASHSEED": hs}
        r = subprocess.run(
            [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
        )
        out.add(r.stdout.strip())
    s = simulate(preset("multiradar", scans=3, truth_sigma_v=1.0), 5)
    out.add(hashlib.sha256(s.plots.x.tobytes() + s.plots.origin.tobytes()).hexdigest())
    assert len(out) == 1


def test_adding_a_sensor_leaves_the_others_draws_unchanged():
    s = preset("crossing", scans=20)
    two = dataclasses.replace(
        s, sensors=(*s.sensors, CartesianSensor(id=7, sigma=30.0)), pd=(0.9, 0.5)
    )
    a, b = simulate(s, 3).plots, simulate(two, 3).plots
    m = b.sensor == 0
    assert np.array_equal(a.x, b.x[m]) and np.array_equal(a.origin, b.origin[m])
    assert b.R is not None  # two Cartesian sigmas: per-plot R
    assert np.allclose(b.R[~m], 900.0 * np.eye(2))
    # within a scan, plots are ordered by sensor id
    for k in range(1, 21):
        assert np.all(np.diff(b.sensor[b.scan == k]) >= 0)


def test_uniform_clutter_positions_are_uniform():
    s = preset("multiradar", scans=30)
    p = simulate(s, 11).plots
    c = p.origin == -1
    r = s.region
    x, y = p.x[c], p.y[c]
    assert abs(c.sum() / 30 / 3 - 50) < 4 * np.sqrt(50 / 90)  # per scan per radar
    assert stats.kstest(x, "uniform", args=(r.xmin, r.xmax - r.xmin)).pvalue > 1e-3
    counts, _ = np.histogram(y, bins=10, range=(r.ymin, r.ymax))
    assert stats.chisquare(counts).pvalue > 1e-3
    # the same test rejects the crossing preset's mixture clutter (the test has power)
    g = simulate(preset("crossing", scans=30), 11).plots
    gx = g.x[g.origin == -1]
    assert stats.kstest(gx, "uniform", args=(-4000, 8000)).pvalue < 1e-6


def test_gmm_clutter_component_means_recovered():
    sklearn_mixture = pytest.importorskip("sklearn.mixture")
    s = preset("crossing")
    p = simulate(s, 2).plots
    z = p.z[p.origin == -1]
    fit = sklearn_mixture.GaussianMixture(4, covariance_type="full", random_state=0, n_init=3).fit(
        z
    )
    truth_means = s.clutter.means
    for m in truth_means:
        d = np.linalg.norm(fit.means_ - m, axis=1)
        assert d.min() < 10.0  # σ ≈ 30 m, ~900 points per component
    assert np.allclose(np.sort(fit.weights_), 0.25, atol=0.04)


def test_multiradar_polar_columns():
    s = preset("multiradar")
    p = simulate(s, 4).plots
    assert sorted(set(p.sensor.tolist())) == [1, 2, 3]
    assert p.range is not None and np.isfinite(p.range).all() and np.isfinite(p.bearing).all()
    assert p.R.shape == (len(p), 2, 2)
    for radar in s.sensors:
        m = p.sensor == radar.id
        back = radar.convert(np.column_stack((p.range[m], p.bearing[m])))
        assert np.allclose(back.z, p.z[m]) and np.allclose(back.R, p.R[m])
    # each radar sees a target from its own side: the long axis of R (cross-range) is
    # perpendicular to the radar's line of sight, so it differs between radars
    tgt = (p.origin == 1) & (p.scan == 1)
    axes = []
    for R, sid in zip(p.R[tgt], p.sensor[tgt], strict=True):
        _, v = np.linalg.eigh(R)
        radar = next(r for r in s.sensors if r.id == sid)
        los = np.asarray(s.targets[0].state)[[0, 2]] - radar.position
        assert abs(v[:, 1] @ los) / np.linalg.norm(los) < 0.05  # long axis ⟂ line of sight
        axes.append(v[:, 1])
    assert abs(axes[0] @ axes[1]) < 0.99


def test_multiradar_every_target_three_plots_per_scan_without_clutter():
    s = preset("multiradar", clutter_rate=0.0)
    assert s.pd == (1.0, 1.0, 1.0)
    p = simulate(s, 0).plots
    assert (p.origin >= 0).all()
    for k in range(1, 11):
        m = p.scan == k
        ids, n = np.unique(p.origin[m], return_counts=True)
        assert ids.tolist() == list(range(1, 11)) and (n == 3).all()
        for tid in ids:
            assert sorted(p.sensor[m][p.origin[m] == tid].tolist()) == [1, 2, 3]


def test_mixed_sensors_have_nan_polar_columns_on_cartesian_rows():
    s = preset("crossing", scans=5)
    mixed = dataclasses.replace(
        s, sensors=(*s.sensors, PolarRadar(1, (0.0, -9000.0))), pd=(0.9, 0.9)
    )
    p = simulate(mixed, 0).plots
    cart = p.sensor == 0
    assert np.isnan(p.range[cart]).all() and np.isfinite(p.range[~cart]).all()
    assert np.allclose(p.R[cart], 1e4 * np.eye(2))


def test_empty_scans_are_listed():
    import dataclasses

    s = dataclasses.replace(preset("crossing", scans=4, clutter="uniform", clutter_rate=0.0),
                            targets=())
    p = simulate(s, 0).plots
    assert len(p) == 0 and p.n_scans == 4
    assert [sc.index for sc in p.scans()] == [1, 2, 3, 4]
    assert isinstance(s.clutter, UniformClutter)


def test_seed_validation():
    with pytest.raises(ValueError, match="seed"):
        simulate(preset("crossing", scans=2), -1)


def test_oversized_overrides_are_refused_before_simulating():
    """Too many scans or plots: a clear error naming the key, not an out-of-memory kill."""
    from mhtrack.errors import short_number
    from mhtrack.scenario import apply_overrides, from_dict
    from mhtrack.scenario.limits import MAX_PLOTS, MAX_SCANS

    with pytest.raises(ValueError, match=rf"^scans: .*more than the maximum {MAX_SCANS} \(MAX_SC"):
        preset("crossing", scans=MAX_SCANS + 1)
    with pytest.raises(ValueError, match=rf"^clutter\.rate: .* maximum {short_number(MAX_PLOTS)} "):
        preset("crossing", clutter_rate=1e9)
    s = from_dict(preset("multiradar").to_dict())
    with pytest.raises(ValueError, match=r"^clutter\.rate: .*3 sensor\(s\) × mean clutter rate"):
        apply_overrides(s, clutter_rate=1e9)
    with pytest.raises(ValueError, match=rf"^scans: .*more than the maximum {MAX_SCANS}"):
        apply_overrides(s, scans=MAX_SCANS + 1)
    # just under the limits is accepted (nothing is simulated here)
    assert apply_overrides(s, clutter_rate=MAX_PLOTS / 3 / 10 - 100).n_scans == 10
