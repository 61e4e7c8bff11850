"""The plug-in interfaces of initiation: a custom Initiator and a custom Fuser get the one
``initiate()`` / ``fuse()`` template, checked against hand-worked results."""

import numpy as np
import pytest

from mhtrack.build import make_initiator
from mhtrack.initiation import (
    FUSED,
    Fuser,
    HoughInitiator,
    Initiator,
    LogicInitiator,
    Window,
)
from mhtrack.records import Scan


def _line_scans(n_scans: int = 4, extra: bool = True) -> list[Scan]:
    """One target on x = 100 + 50 t, y = −20 t (no noise), scans at t = 2k; plus a stray
    plot per scan when ``extra``."""
    scans = []
    for k in range(n_scans):
        t = 2.0 * k
        z = [[100.0 + 50.0 * t, -20.0 * t]] + ([[5000.0, 5000.0 + k]] if extra else [])
        n = len(z)
        scans.append(Scan(k + 10, t, np.array(z), np.zeros(n, np.int64), np.arange(n),
                          np.broadcast_to(np.eye(2) * 25.0, (n, 2, 2)).copy()))
    return scans


class FirstPlotInitiator(Initiator):
    """A custom initiator: the first plot of every scan is one track; it also proposes
    that track's sub-track and a duplicate, which the template must drop."""

    def __init__(self, n_scans: int = 4, bad: bool = False) -> None:
        self.n_scans = n_scans
        self.bad = bad
        self.checked = 0

    def check_parameters(self) -> None:
        self.checked += 1
        if self.bad:
            raise ValueError("bad: must be False")

    def find_tracks(self, window: Window) -> np.ndarray:
        first = window.start[:-1].astype(np.int64)  # flat index of each scan's first plot
        sub = first.copy()
        sub[0] = -1
        return np.array([first, sub, first])


def test_custom_initiator_gets_the_template():
    scans = _line_scans()
    ini = FirstPlotInitiator()
    out = ini.initiate(scans)
    assert ini.checked == 1
    assert len(out) == 1  # the sub-track and the duplicate are gone
    assert out.plots.tolist() == [[0, 0, 0, 0]]  # plot 0 of each scan
    assert out.scans.tolist() == [10, 11, 12, 13] and out.time == 6.0
    # the noise-free line at the last scan (t = 6): x = 400, vx = 50, y = −120, vy = −20
    np.testing.assert_allclose(out.x[0], [400.0, 50.0, -120.0, -20.0], atol=1e-9)
    # four equal-weight plots at τ = −6, −4, −2, 0: var(x) = σ² Σ τ² / det, det = n Στ² − (Στ)²
    tau = np.array([-6.0, -4.0, -2.0, 0.0])
    det = 4 * (tau**2).sum() - tau.sum() ** 2
    np.testing.assert_allclose(out.P[0, 0, 0], 25.0 * (tau**2).sum() / det, rtol=1e-12)
    np.testing.assert_allclose(out.P[0, 1, 1], 25.0 * 4 / det, rtol=1e-12)
    # a Window works as input too, with the same result
    again = ini.initiate(Window.from_scans(scans))
    assert np.array_equal(again.x, out.x) and np.array_equal(again.plots, out.plots)


def test_template_checks_parameters_and_window_length():
    with pytest.raises(ValueError, match="bad: must be False"):
        FirstPlotInitiator(bad=True).initiate(_line_scans())
    with pytest.raises(ValueError, match="window has 3 scans, expected 4"):
        FirstPlotInitiator().initiate(_line_scans(3))


def test_find_tracks_is_required():
    class Incomplete(Initiator):
        n_scans = 4

    with pytest.raises(TypeError, match="find_tracks"):
        Incomplete()  # type: ignore[abstract]


def test_the_p2_initiators_are_initiators():
    box = {"region": (-10_000.0, 10_000.0, -10_000.0, 10_000.0)}
    for method in ("logic", "modified-logic", "hough", "modified-hough"):
        ini = make_initiator(method, **(box if "hough" in method else {}))
        assert isinstance(ini, Initiator)
        assert isinstance(ini, LogicInitiator | HoughInitiator)
        out = ini.initiate(_line_scans(extra=False))
        assert out.plots.tolist() == [[0, 0, 0, 0]]


class OneClusterFuser(Fuser):
    """A custom fuser: all plots of radars 1 and 2 in one cluster, every other plot alone."""

    def fit(self, z, sensor=None, R=None):
        z, sensor = self.check_plots(z, sensor)
        together = np.isin(sensor, [1, 2])
        labels = np.zeros(len(z), np.int64)
        labels[~together] = 1 + np.arange(int((~together).sum()))
        self.labels_ = labels
        return self


def test_custom_fuser_gets_the_fuse_template():
    z = np.array([[0.0, 0.0], [10.0, 20.0], [500.0, 500.0]])
    R = np.array([np.eye(2) * 4.0, np.eye(2) * 16.0, np.eye(2) * 9.0])
    scan = Scan(3, 3.0, z, np.array([1, 2, 7]), np.arange(3), R, np.array([5, 5, -1]))
    out = OneClusterFuser().fuse(scan)
    assert out.labels.tolist() == [0, 0, 1] and out.n_clusters == 2
    # P2's fused plot: the mean, with R̄ = (R₁ + R₂)/n² (hand-worked: (4 + 16)/4 = 5)
    np.testing.assert_allclose(out.scan.z, [[5.0, 10.0], [500.0, 500.0]])
    np.testing.assert_allclose(out.scan.R, [np.eye(2) * 5.0, np.eye(2) * 9.0])
    assert out.scan.sensor.tolist() == [FUSED, 7]  # a one-plot cluster keeps its radar
    assert out.scan.origin.tolist() == [5, -1]
    assert (out.scan.index, out.scan.time) == (3, 3.0)
    assert np.isnan(out.threshold)  # this fuser has no distance threshold
    with pytest.raises(ValueError, match=r"plots must have shape \(n, 2\)"):
        OneClusterFuser().fit(np.zeros((3, 3)))
