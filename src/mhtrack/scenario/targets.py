"""Truth targets of a scenario and their states over the scans.

Two kinds of target:

* :class:`Target` — a constant-velocity target (P1 §1.1) given by its state
  ``x0 = [x, vx, y, vy]`` **at its birth scan**, alive on scans ``birth..death``
  (inclusive). Without process noise its state at scan ``k`` is ``F(T)^(k−birth) x0``
  (exact straight line); with truth process noise ``σv > 0`` it follows
  ``x_{k+1} = F x_k + w_k``, ``w_k ~ N(0, Q(T)·σv²)`` (P1 §1.1; the noise on the truth is
  an option, ``docs/scenarios.md``).
* :class:`RecordedTarget` — an explicit per-scan trajectory (recorded truth such as the
  OpenSky aircraft): the target exists at a scan iff the trajectory has a row for it;
  process noise is never added.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def _check_id(tid: object) -> int:
    if isinstance(tid, bool) or not isinstance(tid, int | np.integer) or int(tid) < 0:
        raise ValueError(f"id: must be an integer >= 0, got {tid!r}")
    return int(tid)


@dataclass(frozen=True)
class Target:
    """Constant-velocity target: ``state`` (x, vx, y, vy) in m and m/s at scan ``birth``;
    alive on scans ``birth..death`` inclusive."""

    id: int
    state: tuple[float, float, float, float]
    birth: int
    death: int

    def __post_init__(self) -> None:
        object.__setattr__(self, "id", _check_id(self.id))
        s = np.asarray(self.state, dtype=float)
        if s.shape != (4,):
            raise ValueError(f"state: expected 4 numbers [x, vx, y, vy], got shape {s.shape}")
        if not np.isfinite(s).all():
            raise ValueError(f"state: must be finite, got {s.tolist()}")
        object.__setattr__(self, "state", tuple(float(v) for v in s))
        for name in ("birth", "death"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | np.integer):
                raise ValueError(f"{name}: expected an integer scan index, got {v!r}")
            object.__setattr__(self, name, int(v))
        if self.birth < 0:
            raise ValueError(f"birth: must be >= 0, got {self.birth}")
        if self.birth > self.death:
            raise ValueError(f"birth: must be <= death ({self.birth} > {self.death})")

    def states(
        self,
        first: int,
        last: int,
        T: float,
        sigma_v: float = 0.0,
        rng: np.random.Generator | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Scans in ``[first, last]`` where the target is alive, and its states there.

        Without noise the position and velocity are closed form,
        ``p_k = p0 + (k − birth)·T·v0``, ``v_k = v0``. With ``sigma_v > 0`` the
        acceleration ``a_j ~ N(0, σv² I₂)`` is drawn for every step from the birth scan on
        (from ``rng``), and ``v_{j+1} = v_j + T a_j``, ``p_{j+1} = p_j + T v_j + T²/2 a_j``
        — the same as ``x_{j+1} = F x_j + G a_j`` with ``G G ᵀσv² = Q`` (P1 §1.1).

        Returns
        -------
        scans : (n,) int64 scan indices; states : (n, 4) ``[x, vx, y, vy]``.
        """
        lo, hi = max(self.birth, first), min(self.death, last)
        if lo > hi:
            return np.zeros(0, np.int64), np.zeros((0, 4))
        x0 = np.asarray(self.state)
        p0, v0 = x0[[0, 2]], x0[[1, 3]]
        steps = np.arange(lo - self.birth, hi - self.birth + 1)
        if sigma_v == 0.0:
            pos = p0 + (steps * T)[:, None] * v0
            vel = np.broadcast_to(v0, pos.shape)
        else:
            if rng is None:
                raise ValueError("a random generator is needed when sigma_v > 0")
            a = rng.normal(scale=sigma_v, size=(int(steps[-1]), 2))
            vel_all = v0 + np.vstack((np.zeros((1, 2)), np.cumsum(T * a, axis=0)))
            dp = T * vel_all[:-1] + 0.5 * T**2 * a
            pos_all = p0 + np.vstack((np.zeros((1, 2)), np.cumsum(dp, axis=0)))
            pos, vel = pos_all[steps], vel_all[steps]
        out = np.column_stack((pos[:, 0], vel[:, 0], pos[:, 1], vel[:, 1]))
        return np.arange(lo, hi + 1, dtype=np.int64), out


@dataclass(frozen=True)
class RecordedTarget:
    """Target with an explicit trajectory: ``states[i]`` (x, vx, y, vy) at scan ``scans[i]``
    (strictly increasing; gaps allowed — the target is absent at scans without a row)."""

    id: int
    scans: tuple[int, ...]
    states: tuple[tuple[float, float, float, float], ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "id", _check_id(self.id))
        sc = np.asarray(self.scans)
        st = np.asarray(self.states, dtype=float)
        if sc.ndim != 1 or len(sc) == 0 or not np.issubdtype(sc.dtype, np.integer):
            raise ValueError("scans: expected a non-empty list of integer scan indices")
        if st.shape != (len(sc), 4):
            raise ValueError(
                f"states: expected {len(sc)} rows of [x, vx, y, vy], got shape {st.shape}"
            )
        if sc[0] < 0 or np.any(np.diff(sc) <= 0):
            raise ValueError("scans: must be >= 0 and strictly increasing")
        if not np.isfinite(st).all():
            raise ValueError("states: must be finite")
        object.__setattr__(self, "scans", tuple(int(v) for v in sc))
        object.__setattr__(self, "states", tuple(tuple(float(v) for v in row) for row in st))

    @property
    def birth(self) -> int:
        return self.scans[0]

    @property
    def death(self) -> int:
        return self.scans[-1]

    def states_in(self, first: int, last: int) -> tuple[np.ndarray, np.ndarray]:
        """Rows with ``first <= scan <= last``: scans (n,) and states (n, 4)."""
        sc = np.asarray(self.scans, dtype=np.int64)
        keep = (sc >= first) & (sc <= last)
        return sc[keep], np.asarray(self.states, dtype=float).reshape(-1, 4)[keep]


AnyTarget = Target | RecordedTarget
