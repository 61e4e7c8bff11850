"""Constants of the P1 §3 reproduction: the trackers and their labels, P1's Table 3 as
printed, the columns of our Table 3, the study's ``run_scenario`` keywords and the output
file names."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

#: Trackers of P1 Table 3, in the paper's row order.
P1_TRACKERS: tuple[str, ...] = ("mht", "mht-gmm", "mht-agmm")
#: Row labels of the trackers.
TRACKER_LABELS = {"mht": "MHT", "mht-gmm": "MHT-GMM", "mht-agmm": "MHT-AGMM"}

#: Where :data:`PAPER_TABLE3` comes from.
PAPER_SOURCE = (
    "P1 (MHT-AGMM: MHT with adaptive-GMM clutter estimation), §3, Table 3 "
    "(\"Performance metrics of three algorithms\"), as printed in the paper; "
    "their machine, their code"
)
#: P1 Table 3, as printed (Tavg, L* in s). P1 gives no OSPA mean (only Fig. 5).
PAPER_TABLE3: dict[str, dict[str, float]] = {
    "mht": {"rcc": 0.8902, "rmc": 0.0056, "rfg": 0.0350, "t_avg": 0.6090,
            "l_min": 38.86, "l_avg": 59.34, "l_max": 76.36},
    "mht-gmm": {"rcc": 0.9301, "rmc": 0.0040, "rfg": 0.0400, "t_avg": 1.0387,
                "l_min": 36.76, "l_avg": 61.94, "l_max": 79.12},
    "mht-agmm": {"rcc": 0.9703, "rmc": 0.0028, "rfg": 0.0200, "t_avg": 0.9365,
                 "l_min": 47.90, "l_avg": 64.44, "l_max": 79.40},
}


@dataclass(frozen=True)
class Metric:
    """A column of Table 3."""

    key: str          #: summary key
    label: str        #: column heading
    higher_better: bool
    digits: int       #: decimals in the tables
    unit: str = ""


#: Columns of our Table 3: P1's seven plus the OSPA mean, the OSPA(2) mean (window of
#: 10 scans, docs/metrics.md) and HOTA (docs/metrics.md).
TABLE3_METRICS: tuple[Metric, ...] = (
    Metric("rcc", "Rcc", True, 4),
    Metric("rmc", "Rmc", False, 4),
    Metric("rfg", "Rfg", False, 4),
    Metric("t_avg", "Tavg (s)", False, 4, " s"),
    Metric("l_min", "Lmin (s)", True, 2, " s"),
    Metric("l_avg", "Lavg (s)", True, 2, " s"),
    Metric("l_max", "Lmax (s)", True, 2, " s"),
    Metric("ospa_mean", "OSPA mean (m)", False, 1, " m"),
    Metric("ospa2_mean", "OSPA(2) mean (m)", False, 1, " m"),
    Metric("hota", "HOTA", True, 4),
)
METRIC_BY_KEY = {m.key: m for m in TABLE3_METRICS}

#: run_scenario keywords of the study (those of ``mhtrack montecarlo``'s defaults, so the
#: job hashes agree with ``mhtrack montecarlo crossing``).
RUN_KWARGS: dict[str, Any] = {"cutoff": 500.0, "order": 2.0, "output": "history"}


@dataclass(frozen=True)
class TrackerSettings:
    """One fidelity level of the study: the MHTConfig changes, the run_scenario keywords,
    the file-name suffix of its outputs and what its rows are called."""

    name: str
    config: dict[str, Any]
    run_kwargs: dict[str, Any]
    suffix: str       #: "" (best: the files of earlier versions) or "-paper"
    row_label: str    #: what a table row of these settings says it is
    description: str


#: ``--tracker-settings paper``: P1's tracker as P1 §1.3, §2, §3 describe it. One
#: constant-velocity model (σv² = 100, ``imm_sigma_v = 0``), P1's P_D, λ_v, κ, σw² and
#: pruning depth (the defaults of :class:`~mhtrack.mht.MHTConfig` on ``crossing``), the
#: online output (the tracks as known at each scan), and the clutter estimators with
#: P1's steps only (P1 §2): one fit per scan on that scan's plots (``window = 1``; the
#: pooling of 5 scans is ours), EM from fresh k-means++ seeds every scan
#: (``warm_start``, ours), no uniform background component (``background``, ours), no
#: contrast test (``min_contrast``, ours), no BIC test of the number of components
#: (``bic``, ours). ``docs/reproduction.md`` lists each and what stays ours.
PAPER_CLUTTER_PARAMS: dict[str, Any] = {"window": 1, "warm_start": False, "background": False,
                                        "min_contrast": 0.0, "bic": False}
TRACKER_SETTINGS: dict[str, TrackerSettings] = {
    "best": TrackerSettings(
        "best", {}, dict(RUN_KWARGS), "", "ours, best settings",
        "our best configuration: two-model IMM (σv = 1 and 10 m/s²), history output, "
        "clutter estimators with our additions (uniform background component, contrast "
        "test; BIC test of the number of components in the AGMM)"),
    "paper": TrackerSettings(
        "paper", {"imm_sigma_v": 0.0},
        {**RUN_KWARGS, "output": "online", "clutter_params": PAPER_CLUTTER_PARAMS},
        "-paper", "ours, P1's settings",
        "P1's tracker: one constant-velocity model (σv² = 100), online output, clutter "
        "estimators with P1's steps only (one fit per scan from fresh seeds, no background "
        "component, no contrast test, no BIC test)"),
}
DEFAULT_SETTINGS = "best"


def settings_file(name: str, settings: TrackerSettings) -> str:
    """``name`` (e.g. ``table3.md``) with the settings' suffix before its extension."""
    if not settings.suffix:
        return name
    stem, dot, ext = name.rpartition(".")
    return f"{stem}{settings.suffix}{dot}{ext}" if dot else f"{name}{settings.suffix}"

MC_DIR = "montecarlo"
TABLE_FILE = "table3.md"
TABLE_JSON = "table3.json"
REPORT_FILE = "report.md"
FIGURES = {
    "fig2": "fig2_truth.png",
    "fig3": "fig3_plots.png",
    "fig4": "fig4_tracks.png",
    "fig5": "fig5_ospa.png",
    "fig6": "fig6_cardinality.png",
}

#: Fixed paragraph of the report: known reasons for the differences.
