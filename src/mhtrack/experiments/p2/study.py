"""Entry point of the P2 (Gong, Dai & Ma 2013, multi-radar track initiation) reproduction:
:func:`reproduce_p2` runs (or resumes) the study's jobs (:mod:`mhtrack.experiments.p2.jobs`)
and writes its outputs; :class:`P2Reproduction` is what it returns.

Outputs in ``DIR``: ``fig2_clustering.png``, ``fig3_ptrue_theta.png``,
``fig4_pfalse_theta.png``, ``fig12_15_initiated.png``, ``tables.md``, ``report.md``,
``results.json``; the job files in ``DIR/jobs/``.
"""

from __future__ import annotations

import json
import math
import os
import time
import traceback
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mhtrack.experiments.montecarlo import atomic_write
from mhtrack.experiments.p2.aggregate import aggregate
from mhtrack.experiments.p2.constants import (
    CHUNK,
    FIGURES,
    JOBS_DIR,
    PAPER_COMPLEXITY,
    PAPER_T_CLUSTER,
    PAPER_T_INIT,
    RATE0,
    RATES,
    REPORT_FILE,
    RESULTS_FILE,
    SIGMA0,
    SIGMAS,
    TABLES_FILE,
    THETAS_DEG,
)
from mhtrack.experiments.p2.figures import _clustering_figure, _curve_figure, _tracks_figure
from mhtrack.experiments.p2.jobs import make_jobs, run_jobs
from mhtrack.experiments.p2.report import report_markdown, tables_markdown


@dataclass
class P2Reproduction:
    out_dir: Path
    results: dict[str, Any]
    computed: int
    skipped: int
    errors: dict[str, str] = field(default_factory=dict)
    wall_seconds: float = 0.0

    @property
    def paths(self) -> list[Path]:
        return [self.out_dir / f for f in (*FIGURES.values(), TABLES_FILE, REPORT_FILE,
                                           RESULTS_FILE, JOBS_DIR)]


def _jsonable(o: Any) -> Any:
    if isinstance(o, dict):
        return {k: _jsonable(v) for k, v in o.items()}
    if isinstance(o, list | tuple):
        return [_jsonable(v) for v in o]
    if isinstance(o, float) and not math.isfinite(o):
        return None
    return o


def reproduce_p2(out_dir: str | os.PathLike[str], runs: int = 10, seed: int = 0, *,
                 thetas: Sequence[float] | None = None, sigmas: Sequence[float] | None = None,
                 rates: Sequence[float] | None = None, executor: str = "local",
                 workers: int | None = None, scheduler: Any = None, progress: bool = False,
                 chunk: int = CHUNK) -> P2Reproduction:
    """Run (or resume) the P2 study into ``out_dir/jobs/`` and write the figures, tables,
    report and ``results.json`` (module docstring). ``thetas`` (deg), ``sigmas`` (m) and
    ``rates`` default to P2's grids."""
    if runs < 1:
        raise ValueError(f"runs must be >= 1, got {runs}")
    if seed < 0:
        raise ValueError(f"seed must be >= 0, got {seed}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    thetas = list(THETAS_DEG if thetas is None else thetas)
    if not all(0 <= x <= 180 for x in thetas):
        raise ValueError("thetas must be in [0, 180] degrees")
    jobs = make_jobs(runs, seed, thetas, SIGMAS if sigmas is None else sigmas,
                     RATES if rates is None else rates, chunk)
    t0 = time.perf_counter()
    results, errors, computed = run_jobs(jobs, out / JOBS_DIR, executor=executor,
                                         workers=workers, scheduler=scheduler,
                                         progress=progress)
    wall = time.perf_counter() - t0
    res = aggregate(jobs, results, thetas)
    res.update(runs=runs, seed=seed, paper={"t_cluster": PAPER_T_CLUSTER,
                                            "t_init": PAPER_T_INIT,
                                            "complexity": PAPER_COMPLEXITY},
               jobs={"total": len(jobs), "computed": computed, "failed": sorted(errors)})
    res = _jsonable(res)
    atomic_write(out / RESULTS_FILE, json.dumps(res, indent=1) + "\n")
    sig = sorted({c["sigma_range"] for c in res["curves"] if c["clutter_rate"] == RATE0})
    rat = sorted({c["clutter_rate"] for c in res["curves"] if c["sigma_range"] == SIGMA0})
    _curve_figure(res, "p_true", [(s, RATE0) for s in sig], lambda s, r: f"σr = {s:g} m",
                  f"P2 Fig. 3: p_true of modified 3/4 logic, λ = {RATE0:g} ({runs} runs)",
                  out / FIGURES["fig3"])
    _curve_figure(res, "p_false", [(SIGMA0, r) for r in rat], lambda s, r: f"λ = {r:g}",
                  f"P2 Fig. 4: p_false of modified 3/4 logic, σr = {SIGMA0:g} m "
                  f"({runs} runs)", out / FIGURES["fig4"])
    for fn, name in ((_clustering_figure, "fig2"), (_tracks_figure, "fig12_15")):
        try:
            fn(seed, out / FIGURES[name])
        except Exception:  # a figure must not lose the study
            atomic_write(out / f"{FIGURES[name]}.error.txt", traceback.format_exc())
    atomic_write(out / TABLES_FILE, tables_markdown(res))
    atomic_write(out / REPORT_FILE, report_markdown(res, runs, seed,
                                                     wall if computed else None))
    return P2Reproduction(out, res, computed, len(jobs) - computed, errors, wall)
