"""Aggregation of the P2 (Gong, Dai & Ma 2013, multi-radar track initiation) study: the
jobs' counts summed into θ curves and the clustering / methods tables, the paired
comparisons of the initiators, and helpers to read a curve back.

P2's false-track probability, as read here (P2 §2.2 gives no formula; its Fig. 4 grows
with θ): ``p_false = false / (false + found)`` — a target on which several true tracks
were initiated in a window counts **once** (P2 counts initiated targets: its track
detection probability is per target, and a duplicate is neither a false track nor a
second detection). ``p_false_tracks = false / tracks`` (every initiated track counted,
duplicates included) is kept beside it: duplicates on true targets dilute it."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from mhtrack.experiments.p2.constants import (
    PAPER_T_CLUSTER,
    PAPER_T_INIT,
    RATE0,
    SIGMA0,
    THETA0,
)
from mhtrack.metrics.paired import compare_paired
from mhtrack.names import INITIATORS

#: Initiator pairs compared run by run (P2 Figs. 12–15: modified beats plain; modified
#: logic ≈ modified Hough).
PAIRS: tuple[tuple[str, str], ...] = (("modified-logic", "logic"),
                                      ("modified-hough", "hough"),
                                      ("modified-logic", "modified-hough"))


def _ratio(a: float, b: float) -> float | None:
    return a / b if b else None


def aggregate(jobs: Sequence[Mapping[str, Any]], results: Mapping[str, Mapping[str, Any]],
              thetas: Sequence[float]) -> dict[str, Any]:
    """Sum the jobs' counts into curves and tables (plain JSON-able dict)."""
    n = len(thetas)
    grid: dict[tuple[float, float], dict[str, Any]] = {}
    clus: dict[str, Any] = {m: {"k_correct": 0, "seconds": 0.0, "clusters": 0}
                            for m in ("adaptive", "random")}
    clus["n_scans"] = 0
    meth: dict[str, Any] = {m: {"found": 0, "false": 0, "tracks": 0, "seconds": 0.0}
                            for m in INITIATORS}
    meth.update(n_targets=0, n_windows=0, n_scans=0, fusion_seconds=0.0)
    per_run: dict[str, list[list[int]]] = {m: [] for m in INITIATORS}
    runs_done: dict[str, int] = {}
    for j in jobs:
        r = results.get(j["name"])
        if r is None:
            continue
        if j["kind"] == "grid":
            key = (j["sigma"], j["rate"])
            g = grid.setdefault(key, {"found": np.zeros(n, np.int64),
                                      "false": np.zeros(n, np.int64),
                                      "tracks": np.zeros(n, np.int64), "n_targets": 0,
                                      "n_windows": 0, "non_monotone_windows": 0, "runs": 0})
            for k in ("found", "false", "tracks"):
                g[k] += np.asarray(r[k], np.int64)
            for k in ("n_targets", "n_windows", "non_monotone_windows"):
                g[k] += r[k]
            g["runs"] += j["stop"] - j["start"]
        elif j["kind"] == "clustering":
            for m in ("adaptive", "random"):
                for k in ("k_correct", "seconds", "clusters"):
                    clus[m][k] += r[m][k]
            clus["n_scans"] += r["n_scans"]
            runs_done["clustering"] = runs_done.get("clustering", 0) + j["stop"] - j["start"]
        else:
            for m in INITIATORS:
                for k in ("found", "false", "tracks", "seconds"):
                    meth[m][k] += r[m][k]
                per_run[m] += r[m].get("per_run", [])
            for k in ("n_targets", "n_windows", "n_scans", "fusion_seconds"):
                meth[k] += r[k]
            runs_done["methods"] = runs_done.get("methods", 0) + j["stop"] - j["start"]

    def curve(g: Mapping[str, Any]) -> dict[str, Any]:
        return {"p_true": [_ratio(int(f), g["n_targets"]) for f in g["found"]],
                "p_false": [_ratio(int(f), int(f) + int(t)) for f, t in zip(
                    g["false"], g["found"], strict=True)],
                "p_false_tracks": [_ratio(int(f), int(t)) for f, t in zip(
                    g["false"], g["tracks"], strict=True)],
                "tracks_per_window": [_ratio(int(t), g["n_windows"]) for t in g["tracks"]],
                "found": g["found"].tolist(), "false": g["false"].tolist(),
                "tracks": g["tracks"].tolist(), "n_targets": g["n_targets"],
                "n_windows": g["n_windows"], "runs": g["runs"],
                "non_monotone_windows": g["non_monotone_windows"]}

    curves = [{"sigma_range": s, "clutter_rate": r, **curve(g)}
              for (s, r), g in sorted(grid.items())]
    ns = clus["n_scans"]
    clustering = {m: {"k_correct_rate": _ratio(clus[m]["k_correct"], ns),
                      "mean_clusters": _ratio(clus[m]["clusters"], ns),
                      "t_scan": _ratio(clus[m]["seconds"], ns),
                      "paper_t_scan": PAPER_T_CLUSTER[m]} for m in ("adaptive", "random")}
    clustering.update(n_scans=ns, runs=runs_done.get("clustering", 0),  # type: ignore[arg-type]
                      clutter_rate=0.0, sigma_range=SIGMA0)
    nw = meth["n_windows"]
    methods = {m: {"p_true": _ratio(meth[m]["found"], meth["n_targets"]),
                   "p_false": _ratio(meth[m]["false"], meth[m]["false"] + meth[m]["found"]),
                   "p_false_tracks": _ratio(meth[m]["false"], meth[m]["tracks"]),
                   "tracks_per_window": _ratio(meth[m]["tracks"], nw),
                   "false_per_window": _ratio(meth[m]["false"], nw),
                   "t_window": _ratio(meth[m]["seconds"], nw),
                   "paper_t_window": PAPER_T_INIT[m]} for m in INITIATORS}
    methods.update(n_windows=nw, runs=runs_done.get("methods", 0),  # type: ignore[arg-type]
                   t_fusion_scan=_ratio(meth["fusion_seconds"], meth["n_scans"]),
                   sigma_range=SIGMA0, clutter_rate=RATE0, theta_deg=THETA0,
                   paired=paired_methods(per_run))
    return {"thetas_deg": [float(x) for x in thetas], "curves": curves,
            "clustering": clustering, "methods": methods}


def paired_methods(per_run: Mapping[str, Sequence[Sequence[int]]]) -> list[dict[str, Any]]:
    """Run-by-run comparisons of :data:`PAIRS` (:func:`mhtrack.metrics.paired.compare_paired`)
    in false tracks per window (lower better) and p_true (higher better); each run's row
    is ``[found, false, tracks, n_targets, n_windows]``."""
    out: list[dict[str, Any]] = []
    for a, b in PAIRS:
        ra, rb = np.asarray(per_run.get(a, []), float), np.asarray(per_run.get(b, []), float)
        if len(ra) < 2 or ra.shape != rb.shape:
            continue
        with np.errstate(divide="ignore", invalid="ignore"):
            for metric, col, den, hb in (("false_per_window", 1, 4, False),
                                         ("p_true", 0, 3, True)):
                c = compare_paired(ra[:, col] / ra[:, den], rb[:, col] / rb[:, den],
                                   metric=metric, name_a=a, name_b=b, higher_better=hb)
                out.append(c.to_dict())
    return out


def curve_for(res: Mapping[str, Any], sigma: float, rate: float) -> dict[str, Any] | None:
    for c in res["curves"]:
        if c["sigma_range"] == sigma and c["clutter_rate"] == rate:
            return c
    return None


def nan_for_none(v: Sequence[float | None]) -> np.ndarray:
    """``v`` as a float array, ``None`` as NaN."""
    return np.array([np.nan if x is None else x for x in v], float)

