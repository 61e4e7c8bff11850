"""Metrics of plot fusion and track initiation (P2 §2.2, §3; ``docs/metrics.md``).

Pure functions on arrays; definitions (also in ``docs/initiation.md``):

**Track truth.** A track initiated in a window of ``N`` scans is *true* for target ``i``
when at least ``min_plots`` (default 3, P2's ``M`` of the 3/4 logic) of its plots
originate from ``i`` (a fused plot's origin is its cluster's majority origin); otherwise
it is *false*. With ``min_plots > N/2`` a track is true for at most one target.

**Initiable targets** of a window: the targets with at least one plot (any radar) in at
least ``min_plots`` of its scans — those a 3/4 rule can start.

Over all windows ``w`` of all runs (``T_w`` the initiable targets, ``K_w`` the tracks):

* ``p_true = Σ_w |{i ∈ T_w : some track of K_w is true for i}| / Σ_w |T_w|`` — share of
  initiable targets whose track is initiated within the window (P2's "probability of
  initiating a true track");
* ``p_false = Σ_w #false / Σ_w (#false + #found_w)`` — P2's "false-track probability"
  as read here, ``#found_w`` the initiable targets with a true track: duplicates count
  **once** (P2 §2.2 gives no formula; P2 counts initiated *targets* — its detection
  probability is per target — so a second true track on a found target is neither a
  false track nor a second detection; read so, p_false grows with θ as P2's Fig. 4);
  NaN when nothing was initiated;
* ``p_false_tracks = Σ_w #false tracks / Σ_w |K_w|`` — share of initiated tracks that are
  false, every duplicate counted (diluted by duplicates on true targets: ours before
  2026-11, kept for comparison);
* ``false_per_run = Σ_w #false / runs``, ``false_per_window = Σ_w #false / #windows``;
* ``duplicates_per_run``: true tracks beyond the first for the same target and window;
* ``t_window``: mean wall-clock seconds an initiator spends on one window (P2 Table 2
  reports totals on its machine).

**Clustering** (per scan): ``k_correct_rate`` = share of scans whose number of clusters
equals the number of targets with at least one plot in the scan; ``fused_error`` = the
distance between each such target's true position and the fused plot assigned to it by
the optimal assignment (``linear_sum_assignment`` on Euclidean distances over all fused
plots); ``purity`` = share of the clusters holding a target plot whose plots all have one
origin.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass

import numpy as np

from mhtrack.metrics._common import pairwise_distance

NO_PLOT_ORIGIN = -2


def track_targets(origins: np.ndarray, min_plots: int = 3) -> np.ndarray:
    """Target id of each track, or ``−1`` for a false track.

    ``origins`` (n, N): origin of each track's plot per scan — a target id ``≥ 0``,
    ``−1`` for clutter, ``−2`` where the track has no plot. A track is true for the
    target id appearing in at least ``min_plots`` of its scans (the most frequent one,
    ties to the lower id).
    """
    o = np.asarray(origins, np.int64)
    if o.ndim != 2:
        raise ValueError(f"origins must have shape (n_tracks, N), got {o.shape}")
    if not (isinstance(min_plots, int | np.integer) and min_plots >= 1):
        raise ValueError(f"min_plots must be an integer >= 1, got {min_plots!r}")
    n = len(o)
    out = np.full(n, -1, np.int64)
    if n == 0:
        return out
    row = np.repeat(np.arange(n), o.shape[1])
    v = o.ravel()
    t = v >= 0
    if not t.any():
        return out
    pairs, counts = np.unique(np.column_stack((row[t], v[t])), axis=0, return_counts=True)
    o2 = np.lexsort((pairs[:, 1], -counts, pairs[:, 0]))
    pairs, counts = pairs[o2], counts[o2]
    first = np.r_[True, pairs[1:, 0] != pairs[:-1, 0]]
    ok = first & (counts >= min_plots)
    out[pairs[ok, 0]] = pairs[ok, 1]
    return out


def initiable_targets(ids: np.ndarray, n_scans_seen: np.ndarray, min_plots: int = 3
                      ) -> np.ndarray:
    """Targets seen (≥ 1 plot) in at least ``min_plots`` scans of the window, from each
    target's id and the number of the window's scans it was seen in."""
    ids = np.asarray(ids, np.int64)
    return np.unique(ids[np.asarray(n_scans_seen) >= min_plots])


@dataclass(frozen=True)
class InitiationMetrics:
    """P2's initiation metrics over many windows and runs (module docstring)."""

    p_true: float
    p_false: float
    p_false_tracks: float
    false_per_run: float
    false_per_window: float
    tracks_per_run: float
    duplicates_per_run: float
    t_window: float
    n_runs: int
    n_windows: int
    n_targets: int
    n_tracks: int

    def to_dict(self) -> dict[str, float | int]:
        return asdict(self)


def initiation_metrics(
    track_target: Sequence[np.ndarray],
    targets: Sequence[np.ndarray],
    *,
    n_runs: int,
    window_seconds: Sequence[float] | None = None,
) -> InitiationMetrics:
    """Aggregate per-window outcomes into :class:`InitiationMetrics`.

    ``track_target[w]``: target id of each track initiated in window ``w`` or ``−1``
    (:func:`track_targets`); ``targets[w]``: the initiable target ids of window ``w``;
    ``n_runs``: number of runs the windows come from; ``window_seconds[w]``: time the
    initiator spent on window ``w``.
    """
    if len(track_target) != len(targets):
        raise ValueError(f"{len(track_target)} windows of tracks but {len(targets)} of targets")
    if not (isinstance(n_runs, int | np.integer) and n_runs >= 1):
        raise ValueError(f"n_runs must be an integer >= 1, got {n_runs!r}")
    n_t = n_found = n_false = n_tracks = n_dup = 0
    for tt, tg in zip(track_target, targets, strict=True):
        tt = np.asarray(tt, np.int64)
        tg = np.unique(np.asarray(tg, np.int64))
        true_ids = tt[tt >= 0]
        found = np.unique(true_ids)
        n_t += len(tg)
        n_found += int(np.isin(tg, found).sum())
        n_false += int((tt < 0).sum())
        n_tracks += len(tt)
        n_dup += len(true_ids) - len(found)
    n_w = len(targets)
    secs = np.asarray(window_seconds if window_seconds is not None else [], float)
    return InitiationMetrics(
        p_true=n_found / n_t if n_t else float("nan"),
        p_false=(n_false / (n_false + n_found) if n_false + n_found else float("nan")),
        p_false_tracks=n_false / n_tracks if n_tracks else float("nan"),
        false_per_run=n_false / n_runs,
        false_per_window=n_false / n_w if n_w else float("nan"),
        tracks_per_run=n_tracks / n_runs,
        duplicates_per_run=n_dup / n_runs,
        t_window=float(secs.mean()) if secs.size else float("nan"),
        n_runs=int(n_runs),
        n_windows=n_w,
        n_targets=n_t,
        n_tracks=n_tracks,
    )


# ---------------------------------------------------------------------- clustering
def fused_plot_errors(fused: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Distance from each true position to the fused plot assigned to it (optimal
    assignment minimising the total distance; a target without a fused plot left, when
    there are fewer fused plots than targets, gets none). Returns (min(n, m),)."""
    from scipy.optimize import linear_sum_assignment
    f = np.asarray(fused, float).reshape(-1, 2)
    t = np.asarray(truth, float).reshape(-1, 2)
    if len(f) == 0 or len(t) == 0:
        return np.zeros(0)
    D = pairwise_distance(t, f)
    r, c = linear_sum_assignment(D)
    return D[r, c]


def cluster_purity(labels: np.ndarray, origin: np.ndarray) -> tuple[int, int]:
    """``(pure, total)``: among clusters holding at least one target plot, how many have
    all their plots from one origin (clutter counts as an origin)."""
    labels = np.asarray(labels, np.int64)
    origin = np.asarray(origin, np.int64)
    if len(labels) == 0:
        return 0, 0
    k = int(labels.max()) + 1
    has_target = np.zeros(k, bool)
    has_target[labels[origin >= 0]] = True
    lo = np.full(k, np.iinfo(np.int64).max)
    hi = np.full(k, np.iinfo(np.int64).min)
    np.minimum.at(lo, labels, origin)
    np.maximum.at(hi, labels, origin)
    pure = has_target & (lo == hi)
    return int(pure.sum()), int(has_target.sum())


@dataclass(frozen=True)
class ClusteringMetrics:
    """Plot-fusion metrics over many scans (module docstring)."""

    k_correct_rate: float
    mean_clusters: float
    mean_targets: float
    fused_error_mean: float
    purity: float
    t_scan: float
    n_scans: int

    def to_dict(self) -> dict[str, float | int]:
        return asdict(self)


def clustering_metrics(
    n_clusters: Sequence[int],
    n_targets: Sequence[int],
    errors: Sequence[np.ndarray],
    purity: Sequence[tuple[int, int]],
    scan_seconds: Sequence[float] | None = None,
) -> ClusteringMetrics:
    """Aggregate per-scan clustering outcomes: cluster and target counts, the
    :func:`fused_plot_errors` and :func:`cluster_purity` of each scan, its fusion time."""
    k = np.asarray(n_clusters, np.int64)
    m = np.asarray(n_targets, np.int64)
    if k.shape != m.shape:
        raise ValueError("n_clusters and n_targets must have one entry per scan")
    e = np.concatenate([np.asarray(x, float).ravel() for x in errors]) if errors else np.zeros(0)
    pu = np.asarray(purity, np.int64).reshape(-1, 2)
    secs = np.asarray(scan_seconds if scan_seconds is not None else [], float)
    return ClusteringMetrics(
        k_correct_rate=float((k == m).mean()) if k.size else float("nan"),
        mean_clusters=float(k.mean()) if k.size else float("nan"),
        mean_targets=float(m.mean()) if m.size else float("nan"),
        fused_error_mean=float(e.mean()) if e.size else float("nan"),
        purity=float(pu[:, 0].sum() / pu[:, 1].sum()) if pu[:, 1].sum() else float("nan"),
        t_scan=float(secs.mean()) if secs.size else float("nan"),
        n_scans=int(k.size),
    )
