"""Tracking performance metrics (``docs/metrics.md``): pure functions, arrays in, small results out.

* :func:`ospa`, :func:`ospa_per_scan` — OSPA (Schuhmacher, Vo & Vo 2008);
* :func:`gospa`, :func:`gospa_per_scan` — GOSPA with α = 2 (Rahmathullah et al. 2017);
* :func:`cardinality_per_scan` — number of tracks vs number of targets per scan;
* :func:`clear_mot` — MOTA, MOTP, identity switches, fragmentations (Bernardin &
  Stiefelhagen 2008);
* :func:`association_metrics` — P1 Table 3's Rcc, Rmc, Rfg and track life Lmin/Lavg/Lmax;
* :func:`tracks_at_times` — asynchronous tracks at the truth's times (latest state no
  older than ``max_age_s``, predicted with constant velocity);
* :func:`ospa2_per_scan` — OSPA(2) over a sliding window of scans (Beard, Vo & Vo 2017);
* :func:`hota` — HOTA, DetA, AssA, LocA for point targets (Luiten et al. 2021);
* :func:`evaluate` — all of the above for one run (asynchronous tracks scored at the
  truth's times).

Definitions and conventions: ``docs/metrics.md``.
"""

from mhtrack.metrics.association import AssociationResult, association_metrics
from mhtrack.metrics.cardinality import CardinalityPerScan, cardinality_per_scan
from mhtrack.metrics.clearmot import (
    DEFAULT_MATCH_DISTANCE,
    CLEARMOTResult,
    MOTMatching,
    clear_mot,
)
from mhtrack.metrics.evaluate import Evaluation, evaluate
from mhtrack.metrics.gospa import GOSPAPerScan, GOSPAResult, gospa, gospa_per_scan
from mhtrack.metrics.hota import HOTAResult, hota
from mhtrack.metrics.ospa import OSPAPerScan, OSPAResult, ospa, ospa_per_scan
from mhtrack.metrics.ospa2 import OSPA2PerScan, ospa2_per_scan
from mhtrack.metrics.resample import DEFAULT_MAX_AGE_S, tracks_at_times

__all__ = [
    "DEFAULT_MATCH_DISTANCE",
    "DEFAULT_MAX_AGE_S",
    "AssociationResult",
    "CLEARMOTResult",
    "CardinalityPerScan",
    "Evaluation",
    "GOSPAPerScan",
    "GOSPAResult",
    "HOTAResult",
    "MOTMatching",
    "OSPA2PerScan",
    "OSPAPerScan",
    "OSPAResult",
    "association_metrics",
    "cardinality_per_scan",
    "clear_mot",
    "evaluate",
    "gospa",
    "gospa_per_scan",
    "hota",
    "ospa",
    "ospa2_per_scan",
    "ospa_per_scan",
    "tracks_at_times",
]
