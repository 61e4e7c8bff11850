"""Hough-transform initiation: votes for a known line, plain vs modified."""

import numpy as np
import pytest

from mhtrack.build import make_initiator
from mhtrack.initiation import HoughInitiator, Window
from mhtrack.records import Scan


def scans_of(points_per_scan):
    out = []
    for k, pts in enumerate(points_per_scan):
        z = np.atleast_2d(np.asarray(pts, float))
        n = len(z)
        out.append(Scan(k + 1, float(k + 1), z, np.zeros(n, np.int64), np.arange(n),
                        np.broadcast_to(np.eye(2) * 400.0, (n, 2, 2)).copy()))
    return out


def test_votes_peak_on_a_known_line():
    # a line with normal angle θ0 = 61° (centre of θ cell 30 of 90) and ρ0 = 1500 m from
    # the centre of the plots' bounding box; points symmetric about the foot of the normal,
    # plus two far corners that fix the box and ρ_max
    th0 = np.radians(61.0)
    n, d = np.array([np.cos(th0), np.sin(th0)]), np.array([-np.sin(th0), np.cos(th0)])
    line = [1500.0 * n + u * d for u in (-300.0, -100.0, 100.0, 300.0)]
    corners = [np.array([-6000.0, -6000.0]), np.array([6000.0, 6000.0])]
    pts = [[p, corners[k % 2]] for k, p in enumerate(line)]
    w = Window.from_scans(scans_of(pts))
    h = HoughInitiator()
    votes, theta, edges, centre = h.accumulate(w)
    np.testing.assert_allclose(centre, [0.0, 0.0], atol=1e-9)
    j, b = np.unravel_index(np.argmax(votes), votes.shape)
    assert votes[j, b] == 4
    assert np.degrees(theta[j]) == pytest.approx(61.0)
    assert edges[b] <= 1500.0 < edges[b + 1]
    # the two corners never share a cell with 4 distinct scans
    assert (votes == 4).sum() <= 3  # only cells around the line's own


REGION = (-5000.0, 5000.0, -5000.0, 5000.0)  # ρ cells of 157 m


def test_straight_track_found_by_both():
    line = [[(200.0 * k, 50.0 * k)] for k in range(4)]
    for method in ("hough", "modified-hough"):
        tr = make_initiator(method, region=REGION).initiate(scans_of(line))
        assert len(tr) == 1, method
        np.testing.assert_array_equal(tr.plots[0], [0, 0, 0, 0])
        np.testing.assert_allclose(tr.x[0], [600.0, 200.0, 150.0, 50.0], atol=1e-6)


def test_modified_hough_rejects_time_disorder_and_speed():
    # collinear, but the target would jump back and forth along the line
    jumbled = [[(0.0, 0.0)], [(400.0, 0.0)], [(200.0, 0.0)], [(600.0, 0.0)]]
    assert len(make_initiator("hough", region=REGION).initiate(scans_of(jumbled))) == 1
    mod = make_initiator("modified-hough", region=REGION)
    assert len(mod.initiate(scans_of(jumbled))) == 0
    too_fast = [[(1000.0 * k, 0.0)] for k in range(4)]  # 1000 m/s > v_max
    assert len(make_initiator("hough", region=REGION).initiate(scans_of(too_fast))) == 1
    assert len(mod.initiate(scans_of(too_fast))) == 0


def test_modified_hough_angle_constraint():
    # legs turning by 10° each scan: inside θ = 20°, outside θ = 5°
    h = np.radians([0.0, 10.0, 20.0])
    z = np.vstack(([0.0, 0.0], np.cumsum(200.0 * np.column_stack((np.cos(h), np.sin(h))),
                                         axis=0)))
    sc = scans_of([[p] for p in z])
    loose = HoughInitiator(modified=True, angle_limit_deg=20.0, region=REGION)
    tight = HoughInitiator(modified=True, angle_limit_deg=5.0, region=REGION)
    assert len(loose.initiate(sc)) == 1
    assert len(tight.initiate(sc)) == 0


def test_votes_count_distinct_scans():
    # four plots on one line but all in the same scan: one vote, no track
    pts = [[(0.0, 0.0), (200.0, 0.0), (400.0, 0.0), (600.0, 0.0)], [(5000.0, 5000.0)],
           [(-5000.0, 5000.0)], [(5000.0, -5000.0)]]
    w = Window.from_scans(scans_of(pts))
    votes, *_ = HoughInitiator().accumulate(w)
    assert votes.max() <= 3
    assert len(make_initiator("hough").initiate(w)) == 0


def test_modified_hough_acceleration_constraint():
    # collinear legs of 200, 200, 350 m in 1 s scans: speed change 150 m/s over the
    # 1 s between the legs' midpoints — rejected by a_max = 100 m/s², kept by 200 or None
    z = [[(0.0, 0.0)], [(200.0, 0.0)], [(400.0, 0.0)], [(750.0, 0.0)]]
    sc = scans_of(z)
    assert len(HoughInitiator(modified=True, region=REGION).initiate(sc)) == 1
    assert len(HoughInitiator(modified=True, region=REGION, accel_max=200.0).initiate(sc)) == 1
    assert len(HoughInitiator(modified=True, region=REGION, accel_max=100.0).initiate(sc)) == 0
    # a constant speed passes any positive a_max
    steady = scans_of([[(200.0 * k, 0.0)] for k in range(4)])
    assert len(HoughInitiator(modified=True, region=REGION, accel_max=1.0).initiate(steady)) == 1
    with pytest.raises(ValueError, match="accel_max"):
        HoughInitiator(modified=True, accel_max=-1.0).check_parameters()


def test_time_order_switch():
    # the jumbled track passes with time_order=False and a loose angle limit only
    jumbled = scans_of([[(0.0, 0.0)], [(400.0, 0.0)], [(200.0, 0.0)], [(600.0, 0.0)]])
    on = HoughInitiator(modified=True, angle_limit_deg=180.0, region=REGION)
    off = HoughInitiator(modified=True, angle_limit_deg=180.0, region=REGION, time_order=False)
    assert len(on.initiate(jumbled)) == 0
    assert len(off.initiate(jumbled)) == 1
