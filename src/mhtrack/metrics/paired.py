"""Paired comparison of two methods run on the same Monte-Carlo runs, and the verdict
sentence every report prints about them.

Run ``i`` of both methods sees the same simulated plots, so the per-run differences
``d_i = a_i − b_i`` (method ``a`` against the reference ``b``) remove the run-to-run
variation of the scenario. From the ``n`` runs where both have a finite value:

* **mean difference** ``d̄`` with the 95 % Student-t interval
  ``d̄ ± t_{0.975, n−1} s_d / √n`` (``s_d`` the sample std, ``ddof = 1``; e.g.
  Montgomery & Runger, *Applied Statistics and Probability for Engineers*, §10-4;
  the interval of ``scipy.stats.ttest_rel``);
* **identical runs**: ``a_i == b_i`` exactly (the two methods gave the same number);
* **sign test**: the runs where ``a`` is better against those where ``b`` is, two-sided
  binomial test at ½ (``scipy.stats.binomtest``), ties left out;
* **Wilcoxon signed-rank test**, two-sided, zero differences left out
  (``scipy.stats.wilcoxon``, ``zero_method="wilcox"``); NaN when every run is a tie.

**Verdict** (:func:`verdict_of`), from the interval alone so that a reader can check it:
``better`` when the whole interval lies on ``a``'s better side of 0 (below 0 when lower is
better, above when higher is better), ``worse`` when it lies on the other side, otherwise
``no detectable difference at n = …``. With one run (no interval) or no runs, no
difference is detectable. The tests' p-values are printed beside it, not used by it; when
the interval gives a verdict that the Wilcoxon test does not confirm at the 0.05 level
(few runs: with ``n ≤ 5`` it cannot; or differences far from normal), the sentence says
so.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

#: Confidence level of the interval.
CONFIDENCE = 0.95
BETTER, WORSE, NO_DIFFERENCE = "better", "worse", "no detectable difference"


@dataclass(frozen=True)
class PairedComparison:
    """Method ``a`` against method ``b`` on one metric over paired runs (module
    docstring). Differences are ``a − b``."""

    metric: str
    a: str
    b: str
    higher_better: bool
    n: int                  #: pairs where both values are finite
    n_identical: int        #: pairs with a_i == b_i
    n_a_better: int
    n_b_better: int
    mean_a: float
    mean_b: float
    mean_diff: float
    std_diff: float         #: sample std of the differences (ddof = 1)
    ci_low: float
    ci_high: float
    sign_p: float
    wilcoxon_p: float
    verdict: str            #: ``better`` / ``worse`` / ``no detectable difference``
    sentence: str

    def to_dict(self) -> dict[str, Any]:
        """The fields as a JSON-ready dict (NaN kept; :mod:`mhtrack.io.jsonsafe` writes it)."""
        return asdict(self)


def t_interval(d: npt.ArrayLike, confidence: float = CONFIDENCE) -> tuple[float, float]:
    """``d̄ ± t_{(1+c)/2, n−1} s_d/√n`` of the finite values of ``d``; ``(NaN, NaN)`` with
    fewer than two values; ``(d̄, d̄)`` when they are all equal."""
    from scipy.stats import t as student_t

    d = np.asarray(d, float)
    d = d[np.isfinite(d)]
    n = d.size
    if n < 2:
        return math.nan, math.nan
    m = float(d.mean())
    s = float(d.std(ddof=1))
    if s == 0.0:
        return m, m
    h = float(student_t.ppf(0.5 + confidence / 2, n - 1)) * s / math.sqrt(n)
    return m - h, m + h


def verdict_of(ci_low: float, ci_high: float, higher_better: bool) -> str:
    """``better`` / ``worse`` / ``no detectable difference`` for ``a − b`` with this
    interval (module docstring)."""
    if not (math.isfinite(ci_low) and math.isfinite(ci_high)):
        return NO_DIFFERENCE
    if ci_low > 0 or ci_high < 0:
        up = ci_low > 0
        return BETTER if up == higher_better else WORSE
    return NO_DIFFERENCE


def interval_decimals(ci_low: float, ci_high: float, digits: int) -> int:
    """Decimals to print a difference's mean and interval with: ``digits``, or, when the
    interval excludes 0 (a ``better``/``worse`` verdict, :func:`verdict_of`), enough for
    the bound nearer 0 to show its first significant digit, ``−⌊log10 min(|lo|,
    |hi|)⌋`` (a value in ``[10^−k, 10^(1−k))`` rounds to at least ``10^−k`` at ``k``
    decimals): the printed bounds then show the side of 0 the verdict reads, never
    ``[-0.00, +0.00]`` beside ``worse``."""
    if not (math.isfinite(ci_low) and math.isfinite(ci_high)) or ci_low <= 0 <= ci_high:
        return digits
    return max(digits, -math.floor(math.log10(min(abs(ci_low), abs(ci_high)))))


#: Most decimals a difference is printed with; a bound nearer 0 than this shows (float
#: noise beside a verdict, say) prints the three numbers in scientific notation.
MAX_DECIMALS = 8


def difference_texts(mean_diff: float, ci_low: float, ci_high: float,
                     digits: int = 3) -> tuple[str, str, str]:
    """The mean difference and its interval's bounds as every report prints them:
    signed, :func:`interval_decimals` decimals, or three significant digits in scientific
    notation beyond :data:`MAX_DECIMALS` (``–`` for NaN)."""
    d = interval_decimals(ci_low, ci_high, digits)
    spec = f"+.{d}f" if d <= MAX_DECIMALS else "+.2e"

    def show(v: float) -> str:
        return f"{v:{spec}}" if math.isfinite(v) else "–"
    return show(mean_diff), show(ci_low), show(ci_high)


def _p(v: float) -> str:
    if not math.isfinite(v):
        return "–"
    return "< 0.001" if v < 0.001 else f"= {v:.3f}"


def verdict_sentence(c: PairedComparison, digits: int = 3, unit: str = "",
                     label: str | None = None) -> str:
    """The sentence a report prints about ``c``: verdict, mean difference, interval,
    runs, identical runs, wins each way and the tests' p-values — every word from the
    numbers."""
    what = label or c.metric
    side = "higher is better" if c.higher_better else "lower is better"
    if c.n == 0:
        return f"{c.a} vs {c.b}, {what}: no paired runs to compare."
    if c.n_identical == c.n:
        return (f"{c.a} vs {c.b}, {what} ({side}): {NO_DIFFERENCE} at n = {c.n} — "
                f"identical in all {c.n} runs.")
    head = (f"{c.a} is {c.verdict} than {c.b}" if c.verdict != NO_DIFFERENCE
            else f"{NO_DIFFERENCE} at n = {c.n}")
    mean, lo, hi = difference_texts(c.mean_diff, c.ci_low, c.ci_high, digits)
    ci = (f"95 % CI [{lo}, {hi}]{unit}" if math.isfinite(c.ci_low)
          else "no interval from one run")
    return (f"{c.a} vs {c.b}, {what} ({side}): {head} — mean difference "
            f"{mean}{unit}, {ci}, n = {c.n} paired runs, "
            f"{c.n_identical} identical; {c.a} better in {c.n_a_better}, worse in "
            f"{c.n_b_better}; sign test p {_p(c.sign_p)}, Wilcoxon p {_p(c.wilcoxon_p)}"
            + (f" (the Wilcoxon test does not confirm it at the {1 - CONFIDENCE:.2f} level: "
               "few runs or non-normal differences)"
               if c.verdict != NO_DIFFERENCE and not c.wilcoxon_p < 1 - CONFIDENCE else "")
            + ".")


def compare_paired(a: npt.ArrayLike, b: npt.ArrayLike, *, metric: str, name_a: str,
                   name_b: str, higher_better: bool, digits: int = 3, unit: str = "",
                   label: str | None = None) -> PairedComparison:
    """Compare paired values ``a[i]``, ``b[i]`` (same run ``i``); pairs with a NaN on
    either side are left out. ``digits``/``unit``/``label`` only shape the sentence."""
    from scipy.stats import binomtest, wilcoxon

    a = np.asarray(a, float).ravel()
    b = np.asarray(b, float).ravel()
    if a.shape != b.shape:
        raise ValueError(f"paired values differ in number: {a.size} vs {b.size}")
    ok = np.isfinite(a) & np.isfinite(b)
    a, b = a[ok], b[ok]
    d = a - b
    n = int(d.size)
    same = int(np.count_nonzero(a == b))
    up, down = int(np.count_nonzero(d > 0)), int(np.count_nonzero(d < 0))
    n_a_better, n_b_better = (up, down) if higher_better else (down, up)
    lo, hi = t_interval(d)
    sign_p = (float(binomtest(n_a_better, n_a_better + n_b_better, 0.5).pvalue)
              if n_a_better + n_b_better else math.nan)
    wil_p = math.nan
    if up + down:
        wil_p = float(wilcoxon(d[d != 0], zero_method="wilcox").pvalue)
    c = PairedComparison(
        metric=metric, a=name_a, b=name_b, higher_better=higher_better, n=n,
        n_identical=same, n_a_better=n_a_better, n_b_better=n_b_better,
        mean_a=float(a.mean()) if n else math.nan, mean_b=float(b.mean()) if n else math.nan,
        mean_diff=float(d.mean()) if n else math.nan,
        std_diff=float(d.std(ddof=1)) if n > 1 else math.nan,
        ci_low=lo, ci_high=hi, sign_p=sign_p, wilcoxon_p=wil_p,
        verdict=verdict_of(lo, hi, higher_better), sentence="")
    return _with_sentence(c, digits, unit, label)


def _with_sentence(c: PairedComparison, digits: int, unit: str,
                   label: str | None) -> PairedComparison:
    from dataclasses import replace

    return replace(c, sentence=verdict_sentence(c, digits, unit, label))


def paired_by_run(records_a: Sequence[Mapping[str, Any]],
                  records_b: Sequence[Mapping[str, Any]], key: str
                  ) -> tuple[np.ndarray, np.ndarray, list[int]]:
    """Values of ``key`` of the runs both record lists hold (matched on ``"run"``, in run
    order), as two float arrays (``None`` → NaN) and the run numbers."""
    def by_run(recs: Sequence[Mapping[str, Any]]) -> dict[int, float]:
        out = {}
        for r in recs:
            v = r.get(key)
            out[int(r["run"])] = math.nan if v is None else float(v)
        return out

    ra, rb = by_run(records_a), by_run(records_b)
    runs = sorted(set(ra) & set(rb))
    return (np.array([ra[i] for i in runs], float), np.array([rb[i] for i in runs], float),
            runs)


__all__ = [
    "BETTER",
    "CONFIDENCE",
    "NO_DIFFERENCE",
    "WORSE",
    "PairedComparison",
    "compare_paired",
    "difference_texts",
    "interval_decimals",
    "paired_by_run",
    "t_interval",
    "verdict_of",
    "verdict_sentence",
]
