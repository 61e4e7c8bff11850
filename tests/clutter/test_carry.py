"""The last fit's Gaussian densities carried to the next warm start: the right columns, and
the floats a recomputation gives, bit for bit."""

import numpy as np
import pytest

from mhtrack.clutter import AGMMClutter, GMMClutter
from mhtrack.clutter.carry import FitColumns, gauss_at
from mhtrack.clutter.density import log_pdf_t, maha_det_t, offsets_t, plots_t
from mhtrack.records import Scan


def same(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("window", [1, 2, 3, 5])
@pytest.mark.parametrize("seed", range(8))
def test_carried_columns_are_the_plots_still_pooled(window: int, seed: int) -> None:
    """Plots labelled by number through a window of scans, some rows of the last scan
    dropped once or twice: the carried columns are the labels the next pool starts with."""
    rng = np.random.default_rng(seed)
    cols = FitColumns()
    win: list[np.ndarray] = []
    label = 0
    fit_pool = np.zeros(0, np.int64)  # the last fit's pool, before any forget
    for _ in range(9):
        n = int(rng.integers(0, 7))
        scan = np.arange(label, label + n)
        label += n
        got = cols.carried(window)
        kept = win[1:] if len(win) == window else win  # the oldest leaves a full window
        if got is not None:
            assert same(fit_pool.take(got[0]), np.concatenate([*kept, scan[:0]]))
        else:
            assert not win or window == 1
        win = [*kept, scan]
        fit_pool = np.concatenate(win)
        cols.record(np.zeros((2, len(fit_pool))), np.zeros(0), list(map(len, win)))
        for _ in range(int(rng.integers(0, 3))):  # forget: rows of the last scan leave
            keep = np.flatnonzero(rng.random(len(win[-1])) < 0.7)
            win[-1] = win[-1][keep]
            cols.drop_last(keep)


@pytest.mark.parametrize("seed", range(10))
def test_gauss_at_with_carried_columns_is_the_recomputation(seed: int) -> None:
    rng = np.random.default_rng(seed)
    k, n_old, n_new = int(rng.integers(1, 9)), int(rng.integers(0, 300)), int(rng.integers(0, 80))
    means = rng.normal(0.0, 2000.0, (k, 2))
    a, c = rng.uniform(1e2, 1e6, k), rng.uniform(1e2, 1e6, k)
    b = rng.uniform(-0.9, 0.9, k) * np.sqrt(a * c)
    cov = np.stack((np.stack((a, b), -1), np.stack((b, c), -1)), 1)
    old = rng.normal(0.0, 3000.0, (n_old, 2))
    maha_old, det = maha_det_t(*offsets_t(plots_t(old), means), cov)
    glp_old = log_pdf_t(maha_old, det)
    cols = np.sort(rng.choice(n_old, int(rng.integers(0, n_old + 1)), replace=False))
    pool = np.concatenate((old[cols], rng.normal(0.0, 3000.0, (n_new, 2))))
    want = gauss_at(plots_t(pool), means, cov, None, True)
    got = gauss_at(plots_t(pool), means, cov, (cols, glp_old, maha_old), True)
    assert same(got[0], want[0]) and same(got[1], want[1])
    assert gauss_at(plots_t(pool), means, cov, (cols, glp_old, maha_old), False)[0] is None


@pytest.mark.parametrize("window", [1, 3, 5])
@pytest.mark.parametrize("cls", [AGMMClutter, GMMClutter])
def test_estimator_with_carried_densities_is_the_one_without(cls: type, window: int,
                                                            monkeypatch) -> None:
    """Whole runs with plots forgotten, empty scans, subsampled pools and outside-gates
    feeding: every fit equals the fit of an estimator that never carries."""
    def run() -> list[bytes]:
        rng = np.random.default_rng(window)
        est = cls(window=window, max_points=150, source="outside-gates")
        out = []
        for k in range(30):
            n = int(rng.integers(0, 70)) if k % 7 else 0
            z = np.concatenate((rng.uniform(-3000.0, 3000.0, (n, 2)),
                                rng.normal((500.0, -800.0), 60.0, (int(rng.integers(0, 12)), 2))))
            est.update(Scan.from_positions(k, float(k), z), rng.random(len(z)) < 0.1)
            est.forget(rng.random(len(z)) < 0.2)
            m = est.mixture_
            out.append(b"" if m is None else m.weights.tobytes() + m.means.tobytes()
                       + m.covariances.tobytes() + est.intensity(z).tobytes())
        return out

    with_carry = run()
    monkeypatch.setattr(FitColumns, "carried", lambda self, window: None)
    assert with_carry == run()
