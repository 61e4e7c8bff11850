"""Markdown of paired comparisons (:mod:`mhtrack.metrics.paired`): one table row per
comparison and the verdict sentences, both generated from the numbers. Every report that
compares two methods prints them through here."""

from __future__ import annotations

import math
from collections.abc import Sequence

from mhtrack.metrics.paired import NO_DIFFERENCE, PairedComparison, difference_texts


def _f(v: float, digits: int) -> str:
    if not math.isfinite(v):
        return "–"
    return f"{v:.{digits}f}"


def _p(v: float) -> str:
    if not math.isfinite(v):
        return "–"
    return "< 0.001" if v < 0.001 else f"{v:.3f}"


def paired_table(comparisons: Sequence[PairedComparison], digits: dict[str, int] | None = None,
                 labels: dict[str, str] | None = None) -> str:
    """A Markdown table: A, B, metric, mean A, mean B, mean difference A − B with its 95 %
    interval, runs (identical), A better / worse, sign and Wilcoxon p, verdict.
    ``digits``/``labels``: decimals and headings per metric key (default 3 / the key);
    the difference and its interval with more decimals where the interval excludes 0
    (:func:`~mhtrack.metrics.paired.difference_texts`, as the verdict sentences)."""
    digits = digits or {}
    labels = labels or {}
    lines = ["| A | B | metric | mean A | mean B | A − B (95 % CI) | runs (identical) | "
             "A better / worse | sign p | Wilcoxon p | verdict |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for c in comparisons:
        d = digits.get(c.metric, 3)
        side = "↑" if c.higher_better else "↓"
        verdict = f"{c.verdict} at n = {c.n}" if c.verdict == NO_DIFFERENCE else c.verdict
        mean, lo, hi = difference_texts(c.mean_diff, c.ci_low, c.ci_high, d)
        ci = f"{mean} [{lo}, {hi}]" if math.isfinite(c.ci_low) else mean
        lines.append(
            f"| {c.a} | {c.b} | {labels.get(c.metric, c.metric)} {side} | "
            f"{_f(c.mean_a, d)} | {_f(c.mean_b, d)} | {ci} | {c.n} ({c.n_identical}) | "
            f"{c.n_a_better} / {c.n_b_better} | {_p(c.sign_p)} | {_p(c.wilcoxon_p)} | "
            f"{verdict} |")
    return "\n".join(lines) + "\n"


def verdict_list(comparisons: Sequence[PairedComparison]) -> str:
    """The comparisons' sentences as a Markdown list."""
    return "\n".join(f"* {c.sentence}" for c in comparisons) + "\n"


def tally(comparisons: Sequence[PairedComparison]) -> str:
    """``better on X, worse on Y, no detectable difference on Z of N metrics`` — counted
    from the verdicts (for one pair of methods)."""
    n = len(comparisons)
    b = sum(c.verdict == "better" for c in comparisons)
    w = sum(c.verdict == "worse" for c in comparisons)
    return (f"better on {b}, worse on {w}, no detectable difference on {n - b - w} of "
            f"{n} metric{'s' if n != 1 else ''}")
