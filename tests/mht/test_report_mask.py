"""The report stage given the step's mask of reporting leaves (chosen and confirmed,
computed once a step) gives what it gives computing the mask itself, and leaves the
mask as it was (it serves the forget hook too)."""

import dataclasses

import numpy as np
import pytest
from leaves_fixture import random_leaves

from mhtrack.mht.identity import Reported
from mhtrack.mht.report import confirmed_windows, report
from mhtrack.records import Scan


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("stepped", [False, True])
def test_report_with_the_mask_equals_report_without(seed, stepped):
    rng = np.random.default_rng(seed)
    lv = random_leaves(rng, 40)
    scan = Scan(7, 3.0, np.zeros((0, 2)), np.zeros(0, np.int64), np.zeros(0, np.int64))
    rows = rng.random(40) < 0.5 if stepped else None
    rep = lv.reported()
    assert np.array_equal(rep, lv.chosen & (lv.track >= 0)) and 0 < rep.sum() < 40
    kept = rep.copy()
    a, b = report(scan, lv, rows, rep), report(scan, lv, rows)
    assert np.array_equal(rep, kept)  # not written in place
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        assert (x is None and y is None) or np.array_equal(x, y), f.name
    assert np.array_equal(confirmed_windows(lv, rep), confirmed_windows(lv))
    for by_id in (False, True):
        p, q = Reported.of(lv, by_id=by_id, reported=rep), Reported.of(lv, by_id=by_id)
        assert np.array_equal(p.track, q.track) and np.array_equal(p.window, q.window)
