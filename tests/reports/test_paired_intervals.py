"""The printed mean difference and 95 % interval of a paired comparison never contradict
its verdict: an interval that excludes 0 prints both bounds non-zero on their side of 0
(more decimals when needed), one format in the verdict sentence, the Markdown table and
the HTML table (:func:`mhtrack.metrics.paired.difference_texts`); intervals that
straddle 0 and large values print as before (the metric's decimals)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from mhtrack.metrics.paired import (
    NO_DIFFERENCE,
    PairedComparison,
    compare_paired,
    difference_texts,
    interval_decimals,
    verdict_of,
    verdict_sentence,
)
from mhtrack.reports.html_study import paired_table as html_table
from mhtrack.reports.paired_text import paired_table


def _comparison(mean: float, lo: float, hi: float, higher_better: bool = False
                ) -> PairedComparison:
    """A hand-made comparison: the verdict by the rule, the sentence at 2 decimals."""
    c = PairedComparison(metric="iae_mean", a="mapgmm-birth", b="mapgmm",
                         higher_better=higher_better, n=5, n_identical=0, n_a_better=1,
                         n_b_better=4, mean_a=3.2, mean_b=3.2, mean_diff=mean,
                         std_diff=0.001, ci_low=lo, ci_high=hi, sign_p=0.375,
                         wilcoxon_p=0.125, verdict=verdict_of(lo, hi, higher_better),
                         sentence="")
    return PairedComparison(**{**c.to_dict(), "sentence": verdict_sentence(c, 2)})


# (mean, low, high, verdict (lower is better), printed at 2 decimals)
CASES = [
    (0.0031, 0.0004, 0.0058, "worse", ("+0.0031", "+0.0004", "+0.0058")),
    (-0.0031, -0.0058, -0.0004, "better", ("-0.0031", "-0.0058", "-0.0004")),
    (0.001, -0.002, 0.004, NO_DIFFERENCE, ("+0.00", "-0.00", "+0.00")),
    (-300.87, -317.21, -284.53, "better", ("-300.87", "-317.21", "-284.53")),
    (0.0123, 0.004, 0.0206, "worse", ("+0.012", "+0.004", "+0.021")),
    (2e-7, 2e-7, 2e-7, "worse", ("+0.0000002",) * 3),  # every run the same tiny amount
]


@pytest.mark.parametrize("mean, lo, hi, verdict, printed", CASES)
def test_sentence_and_tables_print_the_same_bounds(mean, lo, hi, verdict, printed) -> None:
    c = _comparison(mean, lo, hi)
    assert c.verdict == verdict
    m, low, high = printed
    assert difference_texts(mean, lo, hi, 2) == printed
    assert f"mean difference {m}, 95 % CI [{low}, {high}]" in c.sentence
    row = paired_table([c], {"iae_mean": 2}).splitlines()[2]
    assert f"| {m} [{low}, {high}] |" in row
    assert row.endswith(f"| {verdict} |" if verdict != NO_DIFFERENCE
                        else f"| {verdict} at n = 5 |")
    html = html_table([c.to_dict()], {"iae_mean": 2})[1][0]
    assert html[4:7] == [m, f"[{low}, {high}]", verdict]


def test_no_interval_and_nan() -> None:
    assert difference_texts(0.0004, math.nan, math.nan, 2) == ("+0.00", "–", "–")
    assert interval_decimals(math.nan, 0.1, 3) == 3
    assert interval_decimals(0.0, 0.5, 3) == 3  # touches 0: no verdict, no widening


def test_the_reported_case_reads_worse() -> None:
    """Clutter errors a hair apart in every run (the ablation that printed
    ``[-0.00, +0.00]`` beside ``worse``): the bounds now show the difference."""
    b = [3.2104, 2.9871, 3.4512, 3.0040, 3.3318]
    a = [v + d for v, d in zip(b, [0.0021, 0.0035, 0.0012, 0.0028, 0.0019], strict=True)]
    c = compare_paired(a, b, metric="iae_mean", name_a="mapgmm-birth", name_b="mapgmm",
                       higher_better=False, digits=2)
    assert c.verdict == "worse" and 0.0012 < c.ci_low < 0.0013 < 0.0033 < c.ci_high < 0.0034
    # at 2 decimals: "+0.00 [+0.00, +0.00]"; the nearer bound's first digit is the third
    assert "mean difference +0.002, 95 % CI [+0.001, +0.003]" in c.sentence


@given(lo=st.floats(-1e6, 1e6), width=st.floats(0, 1e6), digits=st.integers(0, 6))
def test_printed_bounds_give_the_same_verdict(lo: float, width: float, digits: int) -> None:
    """The verdict read from the printed bounds is the verdict of the interval, for both
    directions; an interval touching or straddling 0 keeps the metric's decimals."""
    hi = lo + width
    _, plo, phi = difference_texts((lo + hi) / 2, lo, hi, digits)
    for hb in (True, False):
        assert verdict_of(float(plo), float(phi), hb) == verdict_of(lo, hi, hb)
    if lo <= 0 <= hi:
        assert interval_decimals(lo, hi, digits) == digits
    else:
        assert float(plo) != 0 and float(phi) != 0


@pytest.mark.parametrize("lo", [5e-324, 1e-17, 3e-9])
def test_bounds_too_near_zero_print_short_in_scientific_notation(lo: float) -> None:
    """A bound nearer 0 than ``MAX_DECIMALS`` shows (float noise beside a verdict): the
    three numbers in scientific notation, short, each on its side of 0."""
    for a, b in ((lo, 2 * lo), (-2 * lo, -lo)):
        texts = difference_texts((a + b) / 2, a, b, 2)
        assert all(len(t) <= 10 and "e" in t for t in texts), texts
        assert [math.copysign(1.0, float(t)) for t in texts[1:]] == \
            [math.copysign(1.0, a), math.copysign(1.0, b)]
        assert float(texts[1]) != 0.0 and float(texts[2]) != 0.0
