"""Geodesy: checked against GeographicLib's pure-Python geodesics (an independent
implementation from PROJ's C code), a Monte-Carlo of the polar errors, and a hand-worked
case."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
from geodesic_reference import WGS84
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.models.geodesy import (
    LocalFrame,
    direct,
    inverse,
    local_to_polar,
    polar_to_local,
)
from mhtrack.models.linalg2 import det2

G = WGS84

# (origin lat, lon, site azimuth from the origin, site distance)
CASES = [(46.8, 8.2, 250.0, 150e3), (46.8, 8.2, 90.0, 150e3), (65.0, 25.0, 30.0, 150e3)]
BEARINGS = np.arange(0.0, 360.0, 22.5)


def site_of(lat0, lon0, az, dist):
    d = G.Direct(lat0, lon0, az, dist)
    return d["lat2"], d["lon2"]


def reference_local(lat0, lon0, lat, lon):
    """x, y of the azimuthal equidistant plane by definition: s sin α1, s cos α1."""
    inv = G.Inverse(lat0, lon0, lat, lon)
    a = math.radians(inv["azi1"])
    return inv["s12"] * math.sin(a), inv["s12"] * math.cos(a)


def reference_jacobian(lat0, lon0, lat, lon):
    """∂(x, y)/∂(e, n) at (lat, lon), closed form from the geodesic from the origin:
    radial (azimuth α2 at the point) keeps α1 and adds to s; transverse (α2 + 90°) turns α1
    by dl/m12, i.e. moves the grid point s·dl/m12 along (cos α1, −sin α1)."""
    inv = G.Inverse(lat0, lon0, lat, lon, G.FULL)
    a1, a2 = math.radians(inv["azi1"]), math.radians(inv["azi2"])
    u = np.array([math.sin(a1), math.cos(a1)])
    t = np.array([math.cos(a1), -math.sin(a1)])
    radial = np.array([math.sin(a2), math.cos(a2)])
    transverse = np.array([math.cos(a2), -math.sin(a2)])
    return np.outer(u, radial) + inv["s12"] / inv["m12"] * np.outer(t, transverse)


def reference_polar_jacobian(lat0, lon0, slat, slon, r, bearing):
    """∂(x, y)/∂(r, θ): ∂(e, n)/∂r = (sin β2, cos β2), ∂(e, n)/∂θ = m12 (cos β2, −sin β2)
    at the plot (β2, m12 of the geodesic from the site), then the frame's Jacobian."""
    d = G.Direct(slat, slon, bearing, r, G.FULL)
    b2 = math.radians(d["azi2"])
    den = np.array([[math.sin(b2), d["m12"] * math.cos(b2)],
                    [math.cos(b2), -d["m12"] * math.sin(b2)]])
    return reference_jacobian(lat0, lon0, d["lat2"], d["lon2"]) @ den


@pytest.mark.parametrize("case", CASES)
def test_polar_positions_match_geographiclib(case):
    """A plot 200 km from a site 150 km from the origin: hypot(x, y) and atan2(x, y) are
    GeographicLib's distance and azimuth from the origin, to far better than 1 m."""
    lat0, lon0, _, _ = case
    frame = LocalFrame(lat0, lon0)
    slat, slon = site_of(*case)
    r = np.full(BEARINGS.size, 200e3)
    z, _ = polar_to_local(frame, slat, slon, r, BEARINGS, 80.0, 0.15)
    worst = 0.0
    for (x, y), b in zip(z, BEARINGS, strict=True):
        d = G.Direct(slat, slon, b, 200e3)
        inv = G.Inverse(lat0, lon0, d["lat2"], d["lon2"])
        assert math.hypot(x, y) == pytest.approx(inv["s12"], abs=1e-3)
        arc = inv["s12"] * math.radians(
            (math.degrees(math.atan2(x, y)) - inv["azi1"] + 180) % 360 - 180
        )
        worst = max(worst, abs(math.hypot(x, y) - inv["s12"]), abs(arc))
    assert worst < 1e-3  # metres; the requirement is 1 m


@pytest.mark.parametrize("case", CASES)
def test_local_to_polar_matches_geographiclib(case):
    lat0, lon0, _, _ = case
    frame = LocalFrame(lat0, lon0)
    slat, slon = site_of(*case)
    rng = np.random.default_rng(3)
    x, y = rng.uniform(-250e3, 250e3, (2, 40))
    r, b = local_to_polar(frame, slat, slon, x, y)
    for xi, yi, ri, bi in zip(x, y, r, b, strict=True):
        lat, lon = frame.to_geodetic(xi, yi)
        assert reference_local(lat0, lon0, float(lat), float(lon)) == pytest.approx(
            (xi, yi), abs=1e-3)
        inv = G.Inverse(slat, slon, float(lat), float(lon))
        assert ri == pytest.approx(inv["s12"], abs=1e-3)
        assert bi == pytest.approx(inv["azi1"] % 360, abs=1e-8)
    z, _ = polar_to_local(frame, slat, slon, r, b, 80.0, 0.15)
    assert np.abs(z - np.column_stack((x, y))).max() < 1e-6


@pytest.mark.parametrize("case", CASES)
def test_round_trips_below_a_millimetre(case):
    lat0, lon0, _, _ = case
    frame = LocalFrame(lat0, lon0)
    rng = np.random.default_rng(1)
    x, y = rng.uniform(-300e3, 300e3, (2, 1000))
    lat, lon = frame.to_geodetic(x, y)
    x2, y2 = frame.to_local(lat, lon)
    assert np.hypot(x2 - x, y2 - y).max() < 1e-3
    lat3, lon3 = frame.to_geodetic(x2, y2)
    d, _ = inverse(lat, lon, lat3, lon3)
    assert d.max() < 1e-3


def test_direct_and_inverse_match_geographiclib():
    lat, lon = direct(46.8, 8.2, [10.0, 200.0], [1e5, 2.5e5])
    d, az = inverse(46.8, 8.2, lat, lon)
    for i, (b, s) in enumerate([(10.0, 1e5), (200.0, 2.5e5)]):
        ref = G.Direct(46.8, 8.2, b, s)
        assert (lat[i], lon[i]) == pytest.approx((ref["lat2"], ref["lon2"]), abs=1e-11)
    assert d == pytest.approx([1e5, 2.5e5], abs=1e-6)
    assert az == pytest.approx([10.0, 200.0], abs=1e-9)


@pytest.mark.parametrize("case", CASES)
def test_frame_jacobian_matches_closed_form(case):
    """The finite-difference ∂(x, y)/∂(e, n) equals the closed form from GeographicLib's
    azi2 and reduced length m12 (convergence and transverse scale) to 1e-7."""
    lat0, lon0, _, _ = case
    frame = LocalFrame(lat0, lon0)
    rng = np.random.default_rng(2)
    x, y = rng.uniform(-250e3, 250e3, (2, 20))
    lat, lon = frame.to_geodetic(x, y)
    J = frame.jacobian(lat, lon)
    for k in range(len(x)):
        ref = reference_jacobian(lat0, lon0, lat[k], lon[k])
        assert np.abs(J[k] - ref).max() < 1e-7


def test_velocity_conversions():
    frame = LocalFrame(46.8, 8.2)
    lat, lon = frame.to_geodetic(200e3, 50e3)  # 200 km east: convergence ≈ 1.9°
    vx, vy = frame.velocity_to_local(lat, lon, 0.0, 250.0)  # due north at 250 m/s
    ref = reference_jacobian(46.8, 8.2, float(lat), float(lon)) @ [0.0, 250.0]
    assert (float(vx), float(vy)) == pytest.approx(tuple(ref), abs=1e-5)
    # true north 200 km east of the origin points towards the pole, left of grid north
    assert math.degrees(math.atan2(vx, vy)) == pytest.approx(-1.9, abs=0.1)
    ve, vn = frame.velocity_to_geodetic(200e3, 50e3, vx, vy)
    assert (float(ve), float(vn)) == pytest.approx((0.0, 250.0), abs=1e-9)
    rng = np.random.default_rng(4)
    x, y, u, v = rng.uniform(-1, 1, (4, 50)) * [[2e5], [2e5], [300], [300]]
    e, n = frame.velocity_to_geodetic(x, y, u, v)
    u2, v2 = frame.velocity_to_local(*frame.to_geodetic(x, y), e, n)
    assert np.abs(np.r_[u2 - u, v2 - v]).max() < 1e-9
    assert e.shape == (50,)


@pytest.mark.parametrize("case", CASES)
def test_polar_covariance_matches_closed_form(case):
    lat0, lon0, _, _ = case
    frame = LocalFrame(lat0, lon0)
    slat, slon = site_of(*case)
    r = np.array([1e3, 50e3, 200e3])
    for b in (0.0, 77.0, 300.0):
        _, R = polar_to_local(frame, slat, slon, r, b, 80.0, 0.15)
        for k, rk in enumerate(r):
            J = reference_polar_jacobian(lat0, lon0, slat, slon, rk, b)
            ref = J @ np.diag([80.0**2, math.radians(0.15) ** 2]) @ J.T
            assert np.abs(R[k] - ref).max() < 1e-6 * np.abs(ref).max()


def naive_covariance(r, bearing_deg, sr, sb_deg):
    """The flat-earth R in the site's own east-north axes, ignoring convergence."""
    t = math.radians(bearing_deg)
    J = np.array([[math.sin(t), r * math.cos(t)], [math.cos(t), -r * math.sin(t)]])
    return J @ np.diag([sr**2, math.radians(sb_deg) ** 2]) @ J.T


def whitened_covariance(samples, R):
    L = np.linalg.cholesky(R)
    w = np.linalg.solve(L, (samples - samples.mean(0)).T).T
    return np.cov(w.T)


def test_polar_covariance_monte_carlo_needs_convergence():
    """Far from the origin (site 150 km east, plot 200 km north of it, 250 km from the
    origin) the sample covariance of exactly converted noisy plots whitened by R is the
    identity within 4 standard errors; whitened by the flat R that ignores the meridian
    convergence (~1.5° there) it is not."""
    frame = LocalFrame(46.8, 8.2)
    slat, slon = site_of(46.8, 8.2, 90.0, 150e3)
    r0, b0, sr, sb = 200e3, 0.0, 80.0, 0.15
    z0, R = polar_to_local(frame, slat, slon, r0, b0, sr, sb)
    assert np.hypot(*z0[0]) == pytest.approx(250e3, rel=0.02)
    n = 20_000
    rng = np.random.default_rng(20240601)
    rr = r0 + rng.normal(0.0, sr, n)
    bb = b0 + rng.normal(0.0, sb, n)
    samples = np.column_stack(frame.to_local(*direct(slat, slon, bb, rr)))
    C = whitened_covariance(samples, R[0])
    se = np.array([[math.sqrt(2 / n), math.sqrt(1 / n)], [math.sqrt(1 / n), math.sqrt(2 / n)]])
    assert np.all(np.abs(C - np.eye(2)) < 4 * se), C
    bad = whitened_covariance(samples, naive_covariance(r0, b0, sr, sb))
    assert abs(bad[0, 1]) > 10 * se[0, 1], bad


def test_hand_worked_site_at_origin_bearing_east():
    """From the origin due east the aeqd plane is exact: y = 0, x = r; R is diagonal with
    σx = σr along the beam and σy = r·σθ across it (the major axis, along y)."""
    frame = LocalFrame(46.8, 8.2)
    r, sr, sb = 100e3, 80.0, 0.15
    z, R = polar_to_local(frame, 46.8, 8.2, r, 90.0, sr, sb)
    assert z[0] == pytest.approx([r, 0.0], abs=1e-6)
    sy = r * math.radians(sb)  # 261.8 m
    assert R[0] == pytest.approx(np.diag([sr**2, sy**2]), rel=1e-7, abs=1e-4)
    w, v = np.linalg.eigh(R[0])
    assert abs(v[1, 1]) == pytest.approx(1.0, abs=1e-9)  # major axis along y
    assert math.sqrt(w[1]) == pytest.approx(sy, rel=1e-8)


def test_shapes_sigmas_per_plot_and_scalars():
    frame = LocalFrame(46.8, 8.2)
    z, R = polar_to_local(frame, 46.4, 6.1, [1e4, 2e4], [10.0, 20.0], [50.0, 100.0], 0.2)
    _, R1 = polar_to_local(frame, 46.4, 6.1, 2e4, 20.0, 100.0, 0.2)
    assert z.shape == (2, 2) and R.shape == (2, 2, 2)
    assert np.array_equal(R[1], R1[0])
    x, y = frame.to_local(46.8, 8.2)
    assert x.shape == () and (float(x), float(y)) == pytest.approx((0.0, 0.0), abs=1e-9)
    assert frame.to_local([[46.8, 47.0]], [[8.2, 8.3]])[0].shape == (1, 2)
    z, R = polar_to_local(frame, 46.4, 6.1, np.empty(0), np.empty(0), 50.0, 0.2)
    assert z.shape == (0, 2) and R.shape == (0, 2, 2)


def test_frame_validates_and_pickles():
    with pytest.raises(ValueError, match="latitude"):
        LocalFrame(95.0, 8.2)
    with pytest.raises(ValueError, match="longitude"):
        LocalFrame(46.8, 181.0)
    f = LocalFrame(46.8, 8.2)
    f.to_local(47.0, 8.0)
    g = pickle.loads(pickle.dumps(f))
    assert g == f
    assert g.to_local(47.0, 8.0) == f.to_local(47.0, 8.0)


@pytest.mark.parametrize("r", [0.0, 1e-300, 1.0, 79.0])
def test_polar_covariance_near_the_site_is_positive_definite(r):
    """Issue 33: a plot at range 0 (or 1e-300) had a singular R (the bearing term is
    ``r²σθ²``). Within ``σr`` of the site the bearing column is GeographicLib's at the
    range ``σr`` (the docstring's rule); the range column is the plot's own."""
    lat0, lon0, _, _ = CASES[0]
    frame = LocalFrame(lat0, lon0)
    slat, slon = site_of(*CASES[0])
    for b in (0.0, 77.0, 300.0):
        _, R = polar_to_local(frame, slat, slon, r, b, 80.0, 0.15)
        jr = reference_polar_jacobian(lat0, lon0, slat, slon, r, b)[:, 0]
        jt = reference_polar_jacobian(lat0, lon0, slat, slon, 80.0, b)[:, 1]
        ref = 80.0**2 * np.outer(jr, jr) + math.radians(0.15) ** 2 * np.outer(jt, jt)
        assert np.abs(R[0] - ref).max() < 1e-6 * np.abs(ref).max()
        assert R[0, 0, 0] > 0 and np.linalg.det(R[0]) > 0
        np.linalg.cholesky(R[0])


def test_polar_covariance_beyond_sigma_range_is_unchanged():
    """At and beyond ``σr`` the rule changes nothing: R is exactly the plain
    ``vr jr jrᵀ + vθ jθ jθᵀ`` of the same central differences (the former code path)."""
    lat0, lon0, _, _ = CASES[0]
    frame = LocalFrame(lat0, lon0)
    slat, slon = site_of(*CASES[0])
    r = np.array([80.0, 81.0, 5e3, 250e3])
    b = np.array([10.0, 100.0, 200.0, 350.0])
    _, R = polar_to_local(frame, slat, slon, r, b, 80.0, 0.15)
    db = math.degrees(1e-4)
    la, lo = direct(slat, slon, np.concatenate((b, b, b + db, b - db)),
                    np.concatenate((r + 10, r - 10, r, r)))
    x, y = frame.to_local(la, lo)
    p = np.stack((x, y), axis=-1).reshape(4, r.size, 2)
    jr, jt = (p[0] - p[1]) / 20.0, (p[2] - p[3]) / 2e-4
    vr, vt = 80.0**2, math.radians(0.15) ** 2
    assert np.array_equal(R[:, 0, 0], vr * jr[:, 0] ** 2 + vt * jt[:, 0] ** 2)
    assert np.array_equal(R[:, 1, 1], vr * jr[:, 1] ** 2 + vt * jt[:, 1] ** 2)
    assert np.array_equal(R[:, 0, 1], vr * jr[:, 0] * jr[:, 1] + vt * jt[:, 0] * jt[:, 1])


@settings(derandomize=True, deadline=None, max_examples=200, database=None)
@given(r=st.floats(0.0, 2e7), b=st.floats(0.0, 360.0), sr=st.floats(1e-9, 1e6),
       sb=st.floats(1e-12, 30.0))
def test_every_valid_polar_plot_has_a_positive_definite_covariance(r, b, sr, sb):
    """Every range, bearing and σ a sensors file and a plots file may hold (their
    documented bounds) gives an R that the tracker's scan check accepts: symmetric,
    finite, ``R[0, 0] > 0`` and ``det2(R) > 0``, Cholesky succeeding."""
    lat0, lon0, _, _ = CASES[0]
    frame = LocalFrame(lat0, lon0)
    slat, slon = site_of(*CASES[0])
    _, R = polar_to_local(frame, slat, slon, r, b, sr, sb)
    assert np.isfinite(R).all() and R[0, 0, 1] == R[0, 1, 0]
    assert R[0, 0, 0] > 0 and det2(R)[0] > 0, (R, det2(R))
    np.linalg.cholesky(R[0])
