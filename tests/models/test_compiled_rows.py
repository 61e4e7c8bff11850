"""The IMM's row loops (:mod:`mhtrack.models.imm_rows`) give the NumPy path's floats bit
for bit: the plain-Python loops always (small stores), numba's compiled loops when numba
is installed; the compiled path stays off for small stores and without numba."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mhtrack.models import imm_rows
from mhtrack.models.imm import CVModelSet, Posterior
from mhtrack.models.motion import States

FIELDS = ("x", "P", "xm", "Pm", "mu")


def _store(rng: np.random.Generator, M: int, r: int) -> States:
    xm = rng.normal(0, 1000, (M, r, 4))
    A = rng.normal(0, 30, (M, r, 4, 4))
    Pm = A @ A.swapaxes(-1, -2) + 100 * np.eye(4)
    mu = rng.dirichlet(np.ones(r), M)
    mu[0] = np.r_[1.0, np.zeros(r - 1)]  # a model at probability 0 (mixing's 1e-300 floor)
    return States(np.zeros((M, 4)), np.zeros((M, 4, 4)), xm, Pm, mu)


def _numpy_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(imm_rows, "MIN_ROWS", 10**12)


def _same(a: States, b: States) -> bool:
    return all(np.array_equal(getattr(a, f), getattr(b, f)) for f in FIELDS)


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), r=st.integers(2, 3), per_row=st.booleans())
def test_plain_loops_equal_numpy(seed: int, r: int, per_row: bool) -> None:
    """The loops, run as plain Python, against the NumPy path (``MIN_ROWS`` not reached:
    the store is small)."""
    rng = np.random.default_rng(seed)
    M = 5
    model = CVModelSet(tuple(np.linspace(0.5, 20, r)), 60.0)
    s = _store(rng, M, r)
    dt = rng.uniform(0.1, 8, M) if per_row else 2.5
    ref = model.predict(s, dt)
    mubar, pim, Q = model.mixing(s.mu, dt)
    out = States(np.empty((M, 4)), np.empty((M, 4, 4)), np.empty(s.xm.shape),
                 np.empty(s.Pm.shape), mubar)
    imm_rows.predict_rows(s.xm, s.Pm, s.mu, mubar, pim, np.atleast_1d(dt),
                          Q if Q.ndim == 4 else Q[None], out.x, out.P, out.xm, out.Pm)
    assert _same(out, ref)
    z = rng.normal(0, 1000, (M, 2))
    R = (np.eye(2) * rng.uniform(1e3, 1e5, (M, 1, 1))) if per_row else 1e4 * np.eye(2)
    ref = model.update(s, z, R)
    out = States(np.empty((M, 4)), np.empty((M, 4, 4)), np.empty(s.xm.shape),
                 np.empty(s.Pm.shape), ref.mu)
    imm_rows.update_rows(s.xm, s.Pm, ref.mu, z, R if R.ndim == 3 else R[None],
                         out.x, out.P, out.xm, out.Pm)
    assert _same(out, ref)


def test_compiled_equal_numpy(monkeypatch: pytest.MonkeyPatch) -> None:
    """numba's loops through :class:`CVModelSet` (predict, update, the children's states
    of the tracker's grow stage) against the NumPy path, scalar and per-row ``dt`` and
    ``R``."""
    pytest.importorskip("numba")
    rng = np.random.default_rng(7)
    M, r = 300, 2
    model = CVModelSet((1.0, 10.0), 100.0)
    s = _store(rng, M, r)
    z = rng.normal(0, 1000, (40, 2))
    for dt, R in ((1.0, 1e4 * np.eye(2)),
                  (rng.uniform(0.1, 5, M), np.eye(2) * rng.uniform(1e3, 1e5, (40, 1, 1)))):
        _numpy_path(monkeypatch)
        ref_pred = model.predict(s, dt)
        parent = np.sort(rng.integers(0, M, 500))
        plot = np.where(rng.random(500) < 0.3, -1, rng.integers(0, 40, 500))
        pair = np.arange(500)
        pmu = rng.dirichlet(np.ones(r), 500)
        post = Posterior(pmu * 3.0, np.full(500, 3.0))
        ref_children = ref_pred.take(parent)
        upd = np.flatnonzero(plot >= 0)
        ref_children.put(upd, model.update(
            ref_pred.take(parent[upd]), z[plot[upd]], R if R.ndim == 2 else R[plot[upd]],
            posterior=post[pair[upd]]))
        zr = z[rng.integers(0, 40, M)]
        Rr = R if R.ndim == 2 else R[rng.integers(0, 40, M)]
        ref_upd = model.update(s, zr, Rr)
        assert model.children_states(ref_pred, parent, plot, pair, z, R, post) is None
        monkeypatch.setattr(imm_rows, "MIN_ROWS", 1)
        assert _same(model.predict(s, dt), ref_pred)
        assert _same(model.update(s, zr, Rr), ref_upd)
        got = model.children_states(ref_pred, parent, plot, pair, z, R, post)
        assert got is not None and _same(got, ref_children)


def test_kernels_off(monkeypatch: pytest.MonkeyPatch) -> None:
    """Below ``MIN_ROWS``, or with ``MHTRACK_COMPILED=0``, the NumPy path."""
    assert imm_rows.kernels(imm_rows.MIN_ROWS - 1) is None
    monkeypatch.setattr(imm_rows, "_TRIED", False)
    monkeypatch.setattr(imm_rows, "_KERNELS", None)
    monkeypatch.setenv("MHTRACK_COMPILED", "0")
    assert imm_rows.kernels(imm_rows.MIN_ROWS) is None


def test_cli_does_not_import_numba() -> None:
    """``mhtrack --help``'s imports and a small tracker's step leave numba unimported."""
    code = ("import sys, mhtrack.cli.main\n"
            "from mhtrack.build import default_config, make_tracker\n"
            "from mhtrack.scenario import preset, simulate\n"
            "sc = preset('crossing', scans=3)\n"
            "trk = make_tracker('mht-agmm', default_config(sc))\n"
            "[trk.step(s) for s in simulate(sc, seed=1).plots.scans()]\n"
            "assert 'numba' not in sys.modules, 'numba imported'\n")
    subprocess.run([sys.executable, "-c", code], check=True)
