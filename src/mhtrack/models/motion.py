"""Constant-velocity motion model (P1 §1.1, eq. 1).

State ``x = [x, vx, y, vy]``; ``F = blkdiag(F1, F1)`` with ``F1 = [[1, T], [0, 1]]`` and
``Q = blkdiag(Q1, Q1)·σv²`` with ``Q1 = [[T⁴/4, T³/2], [T³/2, T²]]`` (piecewise-constant
white acceleration, Bar-Shalom et al. 2001 §6.3.3).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Measurement matrix of a position sensor, ``H = [[1,0,0,0],[0,0,1,0]]`` (P1 §1.1).
H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
#: Indices of position and velocity in the state vector.
POS = np.array([0, 2])
VEL = np.array([1, 3])


@dataclass(frozen=True)
class ConstantVelocity:
    """Nearly-constant-velocity model with acceleration noise standard deviation ``sigma_v``
    (m/s²); P1 uses ``σv² = 100``."""

    sigma_v: float = 10.0

    def __post_init__(self) -> None:
        if not (np.isfinite(self.sigma_v) and self.sigma_v >= 0):
            raise ValueError(f"sigma_v must be finite and >= 0, got {self.sigma_v}")

    @staticmethod
    def F(dt: float) -> np.ndarray:
        """State transition ``F(T)`` (P1 §1.1)."""
        f1 = np.array([[1.0, dt], [0.0, 1.0]])
        return np.kron(np.eye(2), f1)

    def Q(self, dt: float) -> np.ndarray:
        """Process noise covariance ``Q(T)`` (P1 §1.1)."""
        q1 = np.array([[dt**4 / 4, dt**3 / 2], [dt**3 / 2, dt**2]])
        return np.kron(np.eye(2), q1) * self.sigma_v**2

    def propagate(self, x: np.ndarray, dt: float) -> np.ndarray:
        """Noise-free propagation of states ``x`` (…, 4) by ``dt``."""
        return x @ self.F(dt).T
