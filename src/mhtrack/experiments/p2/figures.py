"""Figures of the P2 (Gong, Dai & Ma 2013, multi-radar track initiation) study: the θ
curves of Figs. 3–4, the clustering of Fig. 2 and the four initiators' tracks of
Figs. 12–15 (matplotlib is imported when a figure is drawn)."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from mhtrack.experiments.p2.aggregate import _nan, curve_for
from mhtrack.experiments.p2.constants import METHOD_LABELS, RATE0, SIGMA0, THETA0
from mhtrack.experiments.p2.jobs import _initiators, _seed_of, p2_scenario
from mhtrack.initiation import Window
from mhtrack.initiation.runs import fuse, fused_scans, n_targets_seen
from mhtrack.initiation.window import sliding_windows
from mhtrack.scenario import simulate


def _curve_figure(res: Mapping[str, Any], key: str, points: Sequence[tuple[float, float]],
                  label: Callable[[float, float], str], title: str, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    th = np.asarray(res["thetas_deg"])
    o = np.argsort(th)
    fig, ax = plt.subplots(figsize=(7, 4.6))
    for s, r in points:
        c = curve_for(res, s, r)
        if c is not None:
            ax.plot(th[o], _nan(c[key])[o], "o-", ms=3.5, label=label(s, r))
    ax.axvline(THETA0, color="0.6", ls=":", lw=1, label="θ = 20° (P2's choice)")
    ax.set_xlabel("angle limit θ (deg)")
    ax.set_ylabel(key)
    ax.set_ylim(-0.02, 1.02)
    ax.set_xticks(np.arange(0, 181, 20))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _tracks_figure(seed: int, path: Path) -> None:
    import matplotlib.pyplot as plt

    from mhtrack.plotting.initiation import _finish, _zoom, draw_tracks, draw_window

    sc = p2_scenario(SIGMA0, RATE0)
    rs = _seed_of(seed, 0)
    sim = simulate(sc, rs)
    raw = list(sim.plots.scans())
    fused, _ = fused_scans(raw, "adaptive-kmeans", run_seed=rs)
    win = Window.from_scans(next(iter(sliding_windows(fused, 4))))
    truth = sim.truth.positions[np.isin(sim.truth.scan, win.scans)]
    fig, axes = plt.subplots(2, 2, figsize=(11, 10))
    figno = {"modified-logic": 12, "logic": 13, "hough": 14, "modified-hough": 15}
    for ax, m in zip(axes.ravel(), ("modified-logic", "logic", "hough", "modified-hough"),
                     strict=True):
        tr = _initiators(sc.region.as_tuple())[m].initiate(win)
        draw_window(ax, win)
        draw_tracks(ax, win, tr)
        _zoom(ax, truth)
        _finish(ax, f"P2 Fig. {figno[m]}: {METHOD_LABELS[m]}")
        h, lab = ax.get_legend_handles_labels()
        keep = [i for i, s in enumerate(lab) if "tracks" in s]
        ax.legend([h[i] for i in keep], [lab[i] for i in keep], fontsize=8, loc="upper right")
    fig.suptitle(f"multiradar, run 0, scans {win.scans[0]}–{win.scans[-1]}, σr = 20 m, "
                 f"λ = 50, θ = 20°, adaptive K-means fusion")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def _clustering_figure(seed: int, path: Path) -> None:
    import matplotlib.pyplot as plt

    from mhtrack.plotting.initiation import clustering_figure_for

    # the first scan of run 0 where random-start K-means gets k wrong (P2 Fig. 2(a)
    # shows such a failure); scan 0 if there is none
    sc = p2_scenario(SIGMA0, 0.0)
    rs = _seed_of(seed, 0)
    number = 0
    for i, scan in enumerate(simulate(sc, rs).plots.scans()):
        if fuse(scan, "random", run_seed=rs).n_clusters != n_targets_seen(scan):
            number = i
            break
    fig = clustering_figure_for(sc, seed, scan_number=number)
    fig.savefig(path, dpi=100)
    plt.close(fig)

