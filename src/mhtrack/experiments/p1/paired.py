"""Paired comparisons of the P1 study (:mod:`mhtrack.metrics.paired`): each pair of P1's
trackers on every Table 3 metric but Tavg (a wall-clock time, not a property of the
tracks), and each tracker against itself under the other tracker settings when that study
is in the same directory. Run ``i`` of every tracker and of both settings simulates with
the same seed, so the runs pair."""

from __future__ import annotations

from collections.abc import Mapping

from mhtrack.experiments.montecarlo import MonteCarloResult
from mhtrack.experiments.p1.constants import (
    TABLE3_METRICS,
    TRACKER_LABELS,
    TRACKER_SETTINGS,
    TrackerSettings,
)
from mhtrack.metrics.paired import PairedComparison, compare_paired, paired_by_run

#: Tracker pairs compared, (candidate, reference): P1's claims — MHT-AGMM better than
#: MHT-GMM and than MHT, MHT-GMM better than MHT.
TRACKER_PAIRS: tuple[tuple[str, str], ...] = (
    ("mht-agmm", "mht-gmm"), ("mht-agmm", "mht"), ("mht-gmm", "mht"))
#: Metrics compared in pairs: Table 3's but the timing.
PAIRED_METRICS = tuple(m for m in TABLE3_METRICS if m.key != "t_avg")


def _short(settings: TrackerSettings) -> str:
    return "P1's settings" if settings.name == "paper" else f"{settings.name} settings"


def p1_paired(result: MonteCarloResult, settings: TrackerSettings,
              others: Mapping[str, MonteCarloResult] | None = None) -> list[PairedComparison]:
    """The paired comparisons of the study ``result`` (module docstring)."""
    out: list[PairedComparison] = []
    recs = result.records
    for a, b in TRACKER_PAIRS:
        if a not in recs or b not in recs:
            continue
        for m in PAIRED_METRICS:
            va, vb, _ = paired_by_run(recs[a], recs[b], m.key)
            out.append(compare_paired(
                va, vb, metric=m.key, name_a=TRACKER_LABELS[a], name_b=TRACKER_LABELS[b],
                higher_better=m.higher_better, digits=m.digits, unit=m.unit,
                label=f"{m.label}, {_short(settings)}"))
    for name, other in (others or {}).items():
        ost = TRACKER_SETTINGS[name]
        for t in result.spec.trackers:
            if t not in other.records or t not in recs:
                continue
            for m in PAIRED_METRICS:
                va, vb, _ = paired_by_run(recs[t], other.records[t], m.key)
                out.append(compare_paired(
                    va, vb, metric=m.key,
                    name_a=f"{TRACKER_LABELS[t]} ({_short(settings)})",
                    name_b=f"{TRACKER_LABELS[t]} ({_short(ost)})",
                    higher_better=m.higher_better, digits=m.digits, unit=m.unit,
                    label=m.label))
    return out
