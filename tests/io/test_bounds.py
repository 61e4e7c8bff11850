"""mhtrack.bounds: the bounds and their messages, against hand-worked values."""

from __future__ import annotations

import pytest

from mhtrack import bounds as B


def test_bounds_are_exact_where_they_claim() -> None:
    assert float(B.MAX_INDEX) == B.MAX_INDEX and float(B.MAX_INDEX + 1) == B.MAX_INDEX
    assert B.MAX_CUTOFF ** B.MAX_ORDER < 1e308
    assert B.MAX_MAGNITUDE**2 * 1e6 < 1e308  # sums of a million squares stay finite


@pytest.mark.parametrize(("x", "text"), [
    (2**53, "2^53"), (-(2**53), "-2^53"), (2**63 - 1, "2^63 - 1"), (1e15, "1e15"),
    (0, "0"), (1.5, "1.5"), (12345, "1.2345e4")])
def test_show(x: float, text: str) -> None:
    assert B.show(x) == text


@pytest.mark.parametrize(("v", "problem"), [
    (3, None), (2**53, None), (2**53 + 1,
                               "9007199254740993 is out of range (expected an integer in "
                               "[-2^53, 2^53])"),
    (True, "expected an integer in [-2^53, 2^53], got bool True"),
    (1.0, "expected an integer in [-2^53, 2^53], got float 1.0")])
def test_int_problem(v: object, problem: str | None) -> None:
    assert B.int_problem(v) == problem


@pytest.mark.parametrize(("v", "problem"), [
    (1e15, None), (-3, None), (float("nan"), "nan is out of range (expected a finite number "
                                             "in [-1e15, 1e15])"),
    (10**400, f"{B.clip(repr(10**400))} is out of range (expected a finite number in "
              "[-1e15, 1e15])"),
    ("1", "expected a finite number in [-1e15, 1e15], got str '1'")])
def test_float_problem(v: object, problem: str | None) -> None:
    assert B.float_problem(v) == problem


def test_clip_says_how_long() -> None:
    assert B.clip("x" * 50, 4) == "xxxx… (50 characters)"
    assert B.clip("short") == "short"
