"""One-time code loaded at a live run's start (:mod:`mhtrack.pipeline.preload`): in a
fresh interpreter, after :func:`preload` the lazily imported modules are there, and the
compiled IMM rows (numba, when installed) are compiled for the signatures the tracker
uses — tracker-sized predict, update and children_states calls afterwards with another
model set compile nothing more, and the prediction gives the NumPy path's floats; so is
the clutter map's quadrature (``mapgmm`` on a scan path and on rotating radars compiles
nothing more); with ``MHTRACK_COMPILED=0`` nothing is compiled."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

SRC = str(Path(__file__).resolve().parents[2] / "src")

CHECK = """
import os
import sys
sys.path.insert(0, {src!r})
import numpy as np
from mhtrack.pipeline.preload import LAZY_MODULES, preload
added, used = preload()
missing = [m for m in LAZY_MODULES if m not in sys.modules]
assert not missing, missing
from mhtrack.models import imm_rows
try:
    import numba  # noqa: F401
    has_numba = True
except ImportError:
    has_numba = False
on = os.environ.get("MHTRACK_COMPILED", "1") != "0"
assert used == (has_numba and on), (used, has_numba, on)
if used:
    from mhtrack.models.imm import CVModelSet
    from mhtrack.models.motion import States
    k = imm_rows._KERNELS
    before = {{n: len(f.signatures) for n, f in k.items()}}
    assert all(v >= 1 for v in before.values()), before
    rng = np.random.default_rng(1)
    M, r = imm_rows.MIN_ROWS + 7, 3
    A = rng.normal(0, 30, (M, r, 4, 4))
    s = States(np.zeros((M, 4)), np.zeros((M, 4, 4)), rng.normal(0, 1e3, (M, r, 4)),
               A @ A.swapaxes(-1, -2) + 100 * np.eye(4), rng.dirichlet(np.ones(r), M))
    model = CVModelSet((0.5, 5.0, 20.0), 60.0)
    dt = rng.uniform(0.5, 8, M)
    got = model.predict(s, dt)
    model.predict(s, 2.5)
    rows = np.arange(M)
    z = rng.normal(0, 1e3, (M, 2))
    for R in (100.0 * np.eye(2), np.broadcast_to(50.0 * np.eye(2), (M, 2, 2))):
        _, post = model.gating_scores(got, rows, rows, z, R, np.zeros(M))
        model.update(got, z, R, post)
        model.update(got, z, R)
        assert model.children_states(got, rows, rows, rows, z, R, post) is not None
    assert {{n: len(f.signatures) for n, f in k.items()}} == before, "compiled again"
    imm_rows.MIN_ROWS = 10**12  # the NumPy path
    ref = model.predict(s, dt)
    for f in ("x", "P", "xm", "Pm", "mu"):
        assert np.array_equal(getattr(got, f), getattr(ref, f)), f
from mhtrack.clutter import cell_mass_rows
assert (cell_mass_rows._PATH["kernels"] is not None) == used
if used:  # the clutter map's quadrature: a scan path and rotating radars (polar bases)
    from mhtrack.build import make_clutter_estimator, make_tracker
    from mhtrack.experiments.pipeline import scenario_source
    from mhtrack.scenario import preset, simulate
    q = cell_mass_rows._COMPILED
    before = {{n: len(f.signatures) for n, f in q.items()}}
    assert all(v >= 1 for v in before.values()), before
    est = make_clutter_estimator("mapgmm")
    for scan in simulate(preset("crossing-changing", scans=4), seed=1).plots.scans():
        est.update(scan, None)
    sc = preset("radars-clutter", scans=20)  # 41 frames, 5 quadratures
    src = scenario_source(sc, simulate(sc, seed=1).plots)
    clutter = make_tracker("mht-mapgmm", sensors=src.sensors).clutter
    for frame in scenario_source(sc, simulate(sc, seed=1).plots):
        clutter.update(frame, None)
    assert {{n: len(f.signatures) for n, f in q.items()}} == before, "quadrature compiled again"
print("ok", added, used)
"""


@pytest.mark.parametrize("compiled", [None, "0"])
def test_preload_loads_the_lazy_code(compiled: str | None) -> None:
    env = {k: v for k, v in os.environ.items() if k != "MHTRACK_COMPILED"}
    if compiled is not None:
        env["MHTRACK_COMPILED"] = compiled
    done = subprocess.run([sys.executable, "-c", CHECK.format(src=SRC)],
                          capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("ok")
