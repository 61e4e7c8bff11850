"""The cell-mass quadrature's loops (``mhtrack.clutter.cell_mass_rows``) give the NumPy
path's floats bit for bit: run as plain Python always, numba's compiled loops when numba
is installed; in the plane and in PolarClutter's range and bearing, narrow and broad
Gaussians, near the site, across the polar cut and beyond the map. The NumPy path stays
on for short runs and without numba."""

from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.clutter import cell_mass, cell_mass_rows

PLAIN = {"segments": cell_mass_rows.segment_rows, "products": cell_mass_rows.product_rows}


def _mixture(seed: int, k: int, polar: bool) -> tuple[cell_mass.Cells, tuple[np.ndarray, ...]]:
    """A random map (1–12 rings of 300 m–2 km, 4–64 sectors) and ``k`` Gaussians: σ from
    30 m (narrower than a cell: the stepped boxes) to 20 km, correlated, some at the site
    or beyond the map; in range and ``s = r₀(θ − cut)`` for a polar base."""
    rng = np.random.default_rng(seed)
    dr, rings, sectors = rng.uniform(300, 2000), int(rng.integers(1, 13)), int(rng.integers(4, 65))
    reach = dr * rings
    sig = np.exp(rng.uniform(np.log(30.0), np.log(20_000.0), (k, 2)))
    rho = rng.uniform(-0.9, 0.9, k)
    cov = np.empty((k, 2, 2))
    cov[:, 0, 0], cov[:, 1, 1] = sig[:, 0] ** 2, sig[:, 1] ** 2
    cov[:, 0, 1] = cov[:, 1, 0] = rho * sig[:, 0] * sig[:, 1]
    w = rng.dirichlet(np.ones(k))
    if polar:
        r0, rmin, cut = reach, float(rng.uniform(0, 1500)), float(rng.uniform(0, 2 * np.pi))
        means = np.column_stack([rng.uniform(-0.2, 1.3, k) * reach,
                                 rng.uniform(-0.1, 1.1, k) * 2 * np.pi * r0])
        cells = cell_mass.Cells((0.0, 0.0), dr, rings, sectors, (r0, rmin, cut))
    else:
        site = tuple(rng.normal(0, 5000, 2))
        means = np.asarray(site) + rng.uniform(-1.3, 1.3, (k, 2)) * reach
        means[0] = site  # one at the site: the whole circle of bearings
        cells = cell_mass.Cells(site, dr, rings, sectors)
    return cells, (w, means, cov)


def _path(monkeypatch: pytest.MonkeyPatch, kernels: dict | None) -> None:
    monkeypatch.setitem(cell_mass_rows._PATH, "decided", True)
    monkeypatch.setitem(cell_mass_rows._PATH, "kernels", kernels)


def _both(cells: cell_mass.Cells, mix: tuple[np.ndarray, ...], kernels: dict
          ) -> tuple[np.ndarray, np.ndarray]:
    """``mixture_mass`` on the NumPy path and through ``kernels``."""
    with pytest.MonkeyPatch.context() as mp:
        _path(mp, None)
        ref = cell_mass.mixture_mass(cells, *mix)
        _path(mp, kernels)
        return ref, cell_mass.mixture_mass(cells, *mix)


def _compiled() -> dict:
    """numba's compiled loops, whatever the process decided so far (skip without numba)."""
    pytest.importorskip("numba")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(cell_mass_rows, "_PATH", {"kernels": None, "decided": False, "calls": 0})
        mp.delenv("MHTRACK_COMPILED", raising=False)
        assert cell_mass_rows.load()
    return dict(cell_mass_rows._COMPILED)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), k=st.integers(1, 7), polar=st.booleans())
def test_plain_loops_equal_numpy(seed: int, k: int, polar: bool) -> None:
    """The loops, as plain Python, through ``mixture_mass``: the same floats."""
    ref, got = _both(*_mixture(seed, k, polar), PLAIN)
    assert np.array_equal(got, ref)


@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), k=st.integers(1, 9), polar=st.booleans())
def test_compiled_equal_numpy(seed: int, k: int, polar: bool) -> None:
    """numba's compiled loops through ``mixture_mass``: the same floats."""
    ref, got = _both(*_mixture(seed, k, polar), _compiled())
    assert np.array_equal(got, ref)


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_bounds_compute_nothing(bad: float) -> None:
    """A window with a non-finite bound: the segments loop says so (``mixture_mass`` then
    takes the NumPy path, whose own rule answers) instead of sizing rows from it."""
    lo, hi = np.array([0.2, 1.5]), np.array([3.7, bad])
    x, w, idx, ok = cell_mass_rows.segment_rows(lo, hi, np.array([0.5, 0.5]), lo.copy(),
                                                np.ones(2), cell_mass._X, cell_mass._W,
                                                cell_mass.MAX_STEPS)
    assert not ok and x.size == w.size == idx.size == 0
    lo, hi = np.array([0.2]), np.array([3.7])
    x, w, idx, ok = cell_mass_rows.segment_rows(lo, hi, np.array([0.5]), lo.copy(),
                                                np.ones(1), cell_mass._X, cell_mass._W,
                                                cell_mass.MAX_STEPS)
    ref = cell_mass._batch_segments(lo, hi, np.array([0.5]), lo.copy())
    assert ok and all(np.array_equal(a, b) for a, b in zip((x, w, idx), ref, strict=True))


def test_numpy_path_until_min_calls(monkeypatch: pytest.MonkeyPatch) -> None:
    """Undecided, the first ``MIN_CALLS − 1`` quadratures take the NumPy path; the next
    loads the loops (where numba is installed); ``MHTRACK_COMPILED=0`` keeps NumPy."""
    monkeypatch.setattr(cell_mass_rows, "_PATH", {"kernels": None, "decided": False,
                                                  "calls": 0})
    monkeypatch.setattr(cell_mass_rows, "MIN_CALLS", 3)
    assert cell_mass_rows.kernels() is None and cell_mass_rows.kernels() is None
    try:
        import numba  # noqa: F401
        has_numba = True
    except ImportError:
        has_numba = False
    monkeypatch.delenv("MHTRACK_COMPILED", raising=False)
    assert (cell_mass_rows.kernels() is not None) == has_numba
    assert cell_mass_rows.use(False) is False and cell_mass_rows.kernels() is None
    monkeypatch.setenv("MHTRACK_COMPILED", "0")
    assert cell_mass_rows.use(True) is False and cell_mass_rows.kernels() is None


def test_a_short_run_does_not_import_numba() -> None:
    """A map-calibrated GMM over a short scenario: the NumPy path, numba not imported."""
    code = ("import sys\n"
            "from mhtrack.build import make_clutter_estimator\n"
            "from mhtrack.scenario import preset, simulate\n"
            "est = make_clutter_estimator('mapgmm')\n"
            "for s in simulate(preset('crossing-changing', scans=5), seed=1).plots.scans():\n"
            "    est.update(s, None); est.intensity(s.z)\n"
            "assert 'numba' not in sys.modules, 'numba imported'\n")
    subprocess.run([sys.executable, "-c", code], check=True)


def _quiet_both(cells: cell_mass.Cells, mix: tuple, kernels: dict) -> tuple:
    """:func:`_both` with NumPy's warnings silenced; an exception is returned as its type."""
    out = []
    for k in (None, kernels):
        with pytest.MonkeyPatch.context() as mp, np.errstate(all="ignore"), \
                warnings.catch_warnings():
            warnings.simplefilter("ignore")
            _path(mp, k)
            try:
                out.append(cell_mass.mixture_mass(cells, *mix))
            except Exception as exc:  # compared between the paths
                out.append(type(exc))
    return tuple(out)


@pytest.mark.parametrize("kind", ["plain", "compiled"])
def test_singular_covariance_as_numpy(kind: str) -> None:
    """A covariance of determinant exactly 0 (a line): NaNs in the plane, zeros in range
    and bearing, NumPy's own error for a mean far outside — the loops give the same, not
    a ``ZeroDivisionError`` (the compiled loops use NumPy's error model)."""
    kernels = PLAIN if kind == "plain" else _compiled()
    line = np.array([[[1e6, 1e6], [1e6, 1e6]]])
    cases = [(cell_mass.Cells((0.0, 0.0), 1000.0, 5, 8), [[1500.0, 2000.0]]),
             (cell_mass.Cells((0.0, 0.0), 1000.0, 5, 8, (5000.0, 100.0, 0.0)),
              [[1500.0, 2000.0]]),
             (cell_mass.Cells((0.0, 0.0), 1000.0, 5, 8, (5000.0, 100.0, 0.0)), [[1e7, 1e7]])]
    for cells, mean in cases:
        ref, got = _quiet_both(cells, (np.ones(1), np.array(mean), line), kernels)
        if isinstance(ref, type):
            assert got is ref
        else:
            assert isinstance(got, np.ndarray) and np.array_equal(got, ref, equal_nan=True)


def test_float32_mixture_is_read_as_float64() -> None:
    """A float32 mixture gives the float64 mixture's masses on both paths."""
    cells, (w, means, cov) = _mixture(11, 4, False)
    ref = _both(cells, (w, means, cov), PLAIN)[0]
    f32 = tuple(a.astype(np.float32).astype(float) for a in (w, means, cov))
    ref32 = _both(cells, f32, PLAIN)[0]
    for got in _both(cells, tuple(a.astype(np.float32) for a in (w, means, cov)), PLAIN):
        assert np.array_equal(got, ref32)
    assert np.allclose(ref32, ref, rtol=1e-5, atol=1e-12)
