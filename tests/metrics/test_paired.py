"""Paired comparison: interval against scipy and the closed form, the verdict and its
sentence on constructed cases (identical, clear improvement, clear worsening, noise)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from mhtrack.metrics.paired import (
    BETTER,
    NO_DIFFERENCE,
    WORSE,
    compare_paired,
    paired_by_run,
    t_interval,
    verdict_of,
)


def test_interval_matches_scipy_ttest_rel() -> None:
    rng = np.random.default_rng(3)
    a = rng.normal(10, 2, 30)
    b = a + rng.normal(0.4, 1, 30)
    lo, hi = t_interval(a - b)
    ci = stats.ttest_rel(a, b).confidence_interval(0.95)
    assert lo == pytest.approx(ci.low, rel=1e-12)
    assert hi == pytest.approx(ci.high, rel=1e-12)


def test_interval_closed_form_by_hand() -> None:
    # d = 1, 2, 3: mean 2, s = 1, n = 3; Student t with 2 d.o.f. has the closed-form
    # quantile t_p = (2p − 1) √(2 / (4p(1 − p))), at p = 0.975 ≈ 4.3027
    lo, hi = t_interval([1.0, 2.0, 3.0])
    p = 0.975
    h = (2 * p - 1) * math.sqrt(2 / (4 * p * (1 - p))) / math.sqrt(3)
    assert (lo, hi) == pytest.approx((2 - h, 2 + h), rel=1e-12)


def test_interval_degenerate() -> None:
    assert all(math.isnan(v) for v in t_interval([1.0]))
    assert t_interval([0.5, 0.5, 0.5]) == (0.5, 0.5)


def test_identical_runs() -> None:
    a = np.array([0.9, 0.95, 1.0, 0.8])
    c = compare_paired(a, a.copy(), metric="rcc", name_a="A", name_b="B", higher_better=True)
    assert c.verdict == NO_DIFFERENCE
    assert c.n == 4 and c.n_identical == 4
    assert math.isnan(c.wilcoxon_p) and math.isnan(c.sign_p)
    assert "no detectable difference at n = 4" in c.sentence
    assert "identical in all 4 runs" in c.sentence


def test_clear_improvement_lower_is_better() -> None:
    rng = np.random.default_rng(1)
    b = rng.normal(100, 10, 40)
    a = b - 5 + rng.normal(0, 1, 40)        # OSPA lower: better
    c = compare_paired(a, b, metric="ospa", name_a="AGMM", name_b="GMM",
                       higher_better=False, unit=" m")
    assert c.verdict == BETTER
    assert c.ci_high < 0
    assert c.n_a_better == 40 and c.n_b_better == 0
    assert c.sentence.startswith("AGMM vs GMM, ospa (lower is better): AGMM is better than GMM")
    assert c.wilcoxon_p < 1e-6 and c.sign_p < 1e-6


def test_clear_worsening_higher_is_better() -> None:
    rng = np.random.default_rng(2)
    b = rng.uniform(0.8, 0.9, 25)
    a = b - 0.05 + rng.normal(0, 0.005, 25)  # coverage lower: worse
    c = compare_paired(a, b, metric="rcc", name_a="A", name_b="B", higher_better=True)
    assert c.verdict == WORSE
    assert c.ci_high < 0
    assert "A is worse than B" in c.sentence


def test_noise_gives_no_detectable_difference() -> None:
    rng = np.random.default_rng(4)
    b = rng.normal(50, 5, 20)
    d = rng.normal(0, 1, 20)
    d -= d.mean()                            # mean difference exactly 0
    c = compare_paired(b + d, b, metric="ospa", name_a="A", name_b="B",
                       higher_better=False)
    assert c.verdict == NO_DIFFERENCE
    assert c.ci_low < 0 < c.ci_high
    assert "no detectable difference at n = 20" in c.sentence


def test_one_differing_run_among_identical_is_not_a_difference() -> None:
    # the case: 19 of 20 runs identical, one differs
    a = np.linspace(0.9, 1.0, 20)
    b = a.copy()
    b[7] -= 0.05
    c = compare_paired(a, b, metric="rcc", name_a="AGMM", name_b="GMM", higher_better=True)
    assert c.n_identical == 19
    assert c.verdict == NO_DIFFERENCE
    assert "19 identical" in c.sentence


def test_nan_pairs_left_out() -> None:
    c = compare_paired([1.0, np.nan, 3.0, 4.0], [1.0, 2.0, np.nan, 4.5], metric="m",
                       name_a="A", name_b="B", higher_better=True)
    assert c.n == 2 and c.n_identical == 1


@pytest.mark.parametrize("lo, hi, hb, want", [
    (0.1, 0.2, True, BETTER), (0.1, 0.2, False, WORSE), (-0.2, -0.1, True, WORSE),
    (-0.2, -0.1, False, BETTER), (-0.1, 0.1, True, NO_DIFFERENCE),
    (0.0, 0.1, True, NO_DIFFERENCE), (math.nan, math.nan, True, NO_DIFFERENCE)])
def test_verdict_of_interval(lo: float, hi: float, hb: bool, want: str) -> None:
    assert verdict_of(lo, hi, hb) == want


def test_paired_by_run_matches_runs() -> None:
    ra = [{"run": 0, "x": 1.0}, {"run": 2, "x": 3.0}, {"run": 1, "x": None}]
    rb = [{"run": 2, "x": 30.0}, {"run": 1, "x": 20.0}, {"run": 5, "x": 50.0}]
    a, b, runs = paired_by_run(ra, rb, "x")
    assert runs == [1, 2]
    assert np.isnan(a[0]) and a[1] == 3.0 and b.tolist() == [20.0, 30.0]


def test_small_n_verdict_says_wilcoxon_does_not_confirm() -> None:
    c = compare_paired([1.0, 2.0, 3.0], [2.0, 3.1, 4.0], metric="m", name_a="A", name_b="B",
                       higher_better=True)
    assert c.verdict == WORSE  # the t interval excludes 0
    assert c.wilcoxon_p >= 0.05  # n = 3: the smallest two-sided p is 0.25
    assert "does not confirm it" in c.sentence
