"""Windows, least-squares initial states and removal of dominated tracks."""

import numpy as np

from mhtrack.initiation import Window, least_squares_state, remove_dominated, sliding_windows
from mhtrack.records import Scan


def test_least_squares_state_matches_normal_equations():
    rng = np.random.default_rng(0)
    scans = []
    for k in range(4):
        A = rng.normal(size=(3, 2, 2))
        R = A @ A.transpose(0, 2, 1) + 50.0 * np.eye(2)
        scans.append(Scan(k, 2.0 * k, rng.normal(size=(3, 2)) * 100, np.zeros(3, np.int64),
                          np.arange(3), R))
    w = Window.from_scans(scans)
    flat = np.array([[0, 3, 6, 9], [1, -1, 7, 10], [-1, 5, 8, -1]])
    x, P = least_squares_state(w, flat)
    for i, row in enumerate(flat):
        info, b = np.zeros((4, 4)), np.zeros(4)
        for s, f in enumerate(row):
            if f < 0:
                continue
            H = np.zeros((2, 4))
            H[0, 0] = H[1, 2] = 1.0
            H[0, 1] = H[1, 3] = w.times[s] - w.times[-1]
            Wi = np.linalg.inv(w.R[f])
            info += H.T @ Wi @ H
            b += H.T @ Wi @ w.z[f]
        np.testing.assert_allclose(x[i], np.linalg.solve(info, b), rtol=1e-9)
        np.testing.assert_allclose(P[i], np.linalg.inv(info), rtol=1e-9)


def test_remove_dominated():
    flat = np.array([
        [0, 1, 2, 3],
        [0, 1, 2, -1],   # inside row 0
        [-1, 1, 2, 3],   # inside row 0
        [0, 1, 2, 3],    # duplicate of row 0
        [0, 1, -1, 4],   # differs at the last scan: kept
        [5, 6, 7, -1],
    ])
    np.testing.assert_array_equal(remove_dominated(flat), [1, 0, 0, 0, 1, 1])


def test_sliding_windows():
    scans = [Scan.from_positions(k, float(k), np.zeros((1, 2))) for k in range(10)]
    wins = list(sliding_windows(scans, 4))
    assert len(wins) == 7
    assert [s.index for s in wins[-1]] == [6, 7, 8, 9]
