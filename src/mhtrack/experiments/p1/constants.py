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


#: Columns of our Table 3: P1's seven plus the OSPA mean.
TABLE3_METRICS: tuple[Metric, ...] = (
    Metric("rcc", "Rcc", True, 4),
    Metric("rmc", "Rmc", False, 4),
    Metric("rfg", "Rfg", False, 4),
    Metric("t_avg", "Tavg (s)", False, 4, " s"),
    Metric("l_min", "Lmin (s)", True, 2, " s"),
    Metric("l_avg", "Lavg (s)", True, 2, " s"),
    Metric("l_max", "Lmax (s)", True, 2, " s"),
    Metric("ospa_mean", "OSPA mean (m)", False, 1, " m"),
)
METRIC_BY_KEY = {m.key: m for m in TABLE3_METRICS}

#: run_scenario keywords of the study (those of ``mhtrack montecarlo``'s defaults, so the
#: job hashes agree with ``mhtrack montecarlo crossing``).
RUN_KWARGS: dict[str, Any] = {"cutoff": 500.0, "order": 2.0, "output": "history"}

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
