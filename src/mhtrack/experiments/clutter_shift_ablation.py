"""Why the AGMM does or does not beat the GMM on ``crossing-changing``: each estimator
variant fed every scan of the same simulations (no tracker: every plot, ``forget`` never
called, as ``mhtrack clutter`` feeds it), scored by its clutter error ``∫|κ̂ − κ|``
averaged over the scans and over three phases of the run, and compared run by run with
P1's GMM (:mod:`mhtrack.metrics.paired`). :func:`cached_ablation` keeps the result in
``DIR/ablation.json`` and recomputes it only for other parameters.

The variants switch one design choice at a time: our BIC test of the number of components
(``bic``), P1 eq. 12's mass threshold 0.92 (``mass``), both, and P1's own steps (one fit per
scan from fresh seeds, no background component, no contrast test)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from mhtrack.experiments.jobs import run_seed
from mhtrack.metrics.paired import PairedComparison, compare_paired

P1_STEPS = {"window": 1, "warm_start": False, "background": False, "min_contrast": 0.0,
            "bic": False}
#: Variant name → (estimator, parameters). The first is the reference.
VARIANTS: dict[str, tuple[str, dict[str, Any]]] = {
    "gmm": ("gmm", {}),
    "agmm": ("agmm", {}),
    "agmm, bic=False": ("agmm", {"bic": False}),
    "agmm, mass=0.99": ("agmm", {"mass": 0.99}),
    "agmm, mass=0.99, bic=False": ("agmm", {"mass": 0.99, "bic": False}),
    "gmm, bic=True": ("gmm", {"bic": True}),
    "gmm, P1's steps only": ("gmm", P1_STEPS),
    "agmm, P1's steps only": ("agmm", P1_STEPS),
}
#: Phases of the run (scans, inclusive): before the changes, while they happen, after.
PHASES = ((1, 30), (31, 60), (61, 90))
RESOLUTION = 200


@dataclass
class Ablation:
    """Per variant and run, the mean clutter error (all scans and per phase) and the mean
    number of Gaussian components; the paired comparisons of each variant with ``gmm``."""

    runs: int
    seed: int
    iae: dict[str, list[float]]
    iae_phase: dict[str, list[list[float]]]
    n_components: dict[str, list[float]]
    paired: list[PairedComparison]

    def to_dict(self) -> dict[str, Any]:
        return {"runs": self.runs, "seed": self.seed, "phases": [list(p) for p in PHASES],
                "variants": {k: {"estimator": VARIANTS[k][0], "params": VARIANTS[k][1]}
                             for k in self.iae},
                "iae": self.iae, "iae_phase": self.iae_phase,
                "n_components": self.n_components,
                "paired": [c.to_dict() for c in self.paired]}


def estimator_ablation(scenario: Any, runs: int, seed: int = 0,
                       variants: Mapping[str, tuple[str, dict[str, Any]]] | None = None,
                       resolution: int = RESOLUTION) -> Ablation:
    """Run every variant on runs ``0 … runs−1`` (run ``i`` simulates with
    ``run_seed(seed, i, "spawn")``, the study's seeds) and compare each with the first."""
    from mhtrack.build import make_clutter_estimator
    from mhtrack.metrics.clutter import integrated_absolute_error, true_intensity_grid
    from mhtrack.scenario import simulate

    variants = dict(VARIANTS if variants is None else variants)
    iae: dict[str, list[float]] = {k: [] for k in variants}
    phase: dict[str, list[list[float]]] = {k: [] for k in variants}
    ncomp: dict[str, list[float]] = {k: [] for k in variants}
    grid, cell = scenario.region.grid(int(resolution))
    for i in range(runs):
        sim = simulate(scenario, seed=run_seed(seed, i, "spawn"))
        scans = list(sim.plots.scans())
        truth = [true_intensity_grid(sim, int(s.index), grid) for s in scans]
        index = np.array([int(s.index) for s in scans])
        for k, (name, params) in variants.items():
            est = make_clutter_estimator(name, **params)
            err, counts = [], []
            for scan, true in zip(scans, truth, strict=True):
                est.update(scan, None)
                err.append(integrated_absolute_error(est.intensity(grid), true, cell))
                mix = getattr(est, "mixture_", None)
                counts.append(0 if mix is None else len(mix.weights))
            iae[k].append(float(np.mean(err)))
            phase[k].append(_phase_means(index, np.asarray(err)))
            ncomp[k].append(float(np.mean(counts)))
    ref = next(iter(variants))
    paired = [compare_paired(iae[k], iae[ref], metric="iae_mean", name_a=k, name_b=ref,
                             higher_better=False, digits=2,
                             label="clutter error ∫|κ̂ − κ| (plots/scan)")
              for k in variants if k != ref]
    return Ablation(runs, seed, iae, phase, ncomp, paired)


def _phase_means(scans: np.ndarray, iae: np.ndarray) -> list[float]:
    out = []
    for a, b in PHASES:
        m = (scans >= a) & (scans <= b)
        out.append(float(iae[m].mean()) if m.any() else float("nan"))
    return out


def ablation_markdown(ab: Ablation, names: Sequence[str] | None = None) -> str:
    """A table of the variants (clutter error overall and per phase, components) and the
    verdict sentences against the reference."""
    names = list(ab.iae) if names is None else list(names)
    head = " | ".join(f"scans {a}–{b}" for a, b in PHASES)
    lines = [f"| variant | ∫|κ̂ − κ| | {head} | Gaussians (mean) |",
             "|---|---|" + "---|" * len(PHASES) + "---|"]
    for k in names:
        a = np.array(ab.iae_phase[k], float).reshape(-1, len(PHASES))
        ph = [float(np.mean(c[np.isfinite(c)])) if np.isfinite(c).any() else float("nan")
              for c in a.T]
        lines.append(f"| {k} | {np.mean(ab.iae[k]):.2f} | "
                     + " | ".join("–" if not np.isfinite(v) else f"{v:.2f}" for v in ph)
                     + f" | {np.nanmean(ab.n_components[k]):.2f} |")
    return "\n".join(lines) + "\n\n" + "\n".join(f"* {c.sentence}" for c in ab.paired) + "\n"


ABLATION_FILE = "ablation.json"


def cached_ablation(out_dir: Any, scenario: Any, runs: int, seed: int = 0,
                    resolution: int = RESOLUTION) -> Ablation:
    """:func:`estimator_ablation`, read back from ``out_dir/ablation.json`` when that holds
    the same scenario, runs, seed, resolution and variants, else computed and written."""
    import json
    from pathlib import Path

    from mhtrack.io.atomic import atomic_write
    from mhtrack.io.jsonsafe import to_jsonable
    from mhtrack.metrics.paired import PairedComparison

    path = Path(out_dir) / ABLATION_FILE
    key = {"scenario": scenario.to_dict(), "runs": runs, "seed": seed,
           "resolution": resolution, "variants": VARIANTS}
    key = json.loads(json.dumps(to_jsonable(key)))
    if path.is_file():
        d = json.loads(path.read_text(encoding="utf-8"))
        if d.get("key") == key:
            r = d["result"]
            return Ablation(runs, seed, r["iae"], r["iae_phase"], r["n_components"],
                            [PairedComparison(**{k: (float("nan") if v is None else v)
                                                 for k, v in c.items()})
                             for c in r["paired"]])
    ab = estimator_ablation(scenario, runs, seed, resolution=resolution)
    atomic_write(path, json.dumps(to_jsonable({"key": key, "result": ab.to_dict()}),
                                  indent=1) + "\n")
    return ab
