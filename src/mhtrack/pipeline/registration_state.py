"""The bias estimation's full state as JSON (a live checkpoint's ``extra["bias"]``,
:mod:`mhtrack.pipeline.checkpoint`): the estimator's state and covariance, the
cluster-robust sums, the radars already applied, and each track's last plot per sensor,
so that a resumed run pairs and corrects exactly as a run never stopped.
:func:`restore_state` checks every field of a state read back (a checkpoint is input:
a wrong shape, a non-finite number or a covariance that is not one is refused, naming
the field).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mhtrack.pipeline.registration import Registration, _Plot

#: Version of the bias state.
STATE_FORMAT = 1


def _plot(p: _Plot) -> list[Any]:
    return [p.t, p.sensor, None if np.isnan(p.r) else p.r, None if np.isnan(p.b) else p.b,
            None if p.z is None else p.z.tolist(), None if p.R is None else p.R.tolist()]


def encode_state(reg: Registration) -> dict[str, Any]:
    """``reg``'s state as JSON (floats to the bit: JSON keeps Python's round-trip form)."""
    e = reg.estimator
    return {
        "format": STATE_FORMAT, "ids": list(e.ids), "b": e.b.tolist(), "P": e.P.tolist(),
        "P0_inv": e.P0_inv.tolist(), "meat": e.meat.tolist(),
        "clusters": [[k, a.tolist(), A.tolist(), None if not np.isfinite(t) else t]
                     for k, (a, A, t) in e.clusters.items()],
        "n_clusters": e.n_clusters, "t": e.t, "used": [[k, v] for k, v in e.used.items()],
        "rejected": e.rejected, "pairs": reg.pairs,
        "settled": [[k, v] for k, v in reg.settled.items()],
        "last": [[tid, [_plot(p) for p in d.values()]] for tid, d in reg._last.items()],
    }


def _num(x: Any, field: str, *, none: bool = False) -> float | None:
    if x is None and none:
        return None
    if isinstance(x, bool) or not isinstance(x, int | float) or not np.isfinite(x):
        raise ValueError(f"field {field!r}: expected a finite number, got {x!r}")
    return float(x)


def _int(x: Any, field: str) -> int:
    if isinstance(x, bool) or not isinstance(x, int):
        raise ValueError(f"field {field!r}: expected an integer, got {x!r}")
    return x


def _array(x: Any, shape: tuple[int, ...], field: str) -> np.ndarray:
    try:
        a = np.array(x, float)
    except (TypeError, ValueError):
        raise ValueError(f"field {field!r}: expected numbers of shape {shape}") from None
    if a.shape != shape or not np.all(np.isfinite(a)):
        raise ValueError(f"field {field!r}: expected finite numbers of shape {shape}, got "
                         f"shape {a.shape}")
    return a


def _covariance(x: Any, n: int, field: str) -> np.ndarray:
    a = _array(x, (n, n), field)
    if not np.allclose(a, a.T, rtol=1e-9, atol=0) or (
            n and np.linalg.eigvalsh((a + a.T) / 2)[0] < -1e-9 * max(1.0, np.abs(a).max())):
        raise ValueError(f"field {field!r}: not a covariance (symmetric, ≥ 0)")
    return a


def _read_plot(x: Any, field: str) -> _Plot:
    if not isinstance(x, list) or len(x) != 6:
        raise ValueError(f"field {field!r}: expected [t, sensor, r, b, z, R]")
    t, sid, r, b, z, R = x
    p = _Plot(_num(t, field), _int(sid, field))  # type: ignore[arg-type]
    p.r = np.nan if r is None else _num(r, field)  # type: ignore[assignment]
    p.b = np.nan if b is None else _num(b, field)  # type: ignore[assignment]
    p.z = None if z is None else _array(z, (2,), field)
    p.R = None if R is None else _covariance(R, 2, field)
    if p.z is None and (np.isnan(p.r) or np.isnan(p.b)):
        raise ValueError(f"field {field!r}: a plot needs (r, b) or z")
    return p


def restore_state(reg: Registration, d: Any) -> None:
    """Set ``reg`` (built for the same sensors and reference) to the state ``d`` of
    :func:`encode_state`; :class:`ValueError` naming the field when ``d`` is not one."""
    if not isinstance(d, dict) or d.get("format") != STATE_FORMAT:
        raise ValueError(f"not a bias state of format {STATE_FORMAT}")
    e = reg.estimator
    if d.get("ids") != list(e.ids):
        raise ValueError(f"field 'ids': the state estimates radars {d.get('ids')!r}, this "
                         f"run {list(e.ids)} (another sensors file or reference)")
    n = len(e.b)
    try:
        b, P = _array(d["b"], (n,), "b"), _covariance(d["P"], n, "P")
        P0_inv, meat = _covariance(d["P0_inv"], n, "P0_inv"), _covariance(d["meat"], n, "meat")
        clusters: dict[int, list[Any]] = {}
        for i, c in enumerate(d["clusters"]):
            f = f"clusters[{i}]"
            if not isinstance(c, list) or len(c) != 4:
                raise ValueError(f"field {f!r}: expected [key, alpha, A, t]")
            t = _num(c[3], f, none=True)
            clusters[_int(c[0], f)] = [_array(c[1], (n,), f), _covariance(c[2], n, f),
                                       -np.inf if t is None else t]
        used = {_int(k, "used"): _int(v, "used") for k, v in d["used"]}
        settled = {_int(k, "settled"): _num(v, "settled", none=True) for k, v in d["settled"]}
        if set(used) != set(e.ids) or not set(settled) <= set(e.ids):
            raise ValueError("field 'used'/'settled': radars not those estimated")
        last = {}
        for i, (tid, plots) in enumerate(d["last"]):
            ps = [_read_plot(p, f"last[{i}]") for p in plots]
            last[_int(tid, f"last[{i}]")] = {p.sensor: p for p in ps}
        counts = {k: _int(d[k], k) for k in ("n_clusters", "rejected", "pairs")}
        t = _num(d["t"], "t", none=True)
    except KeyError as k:
        raise ValueError(f"field {k.args[0]!r} missing") from None
    except (TypeError, ValueError) as x:
        if isinstance(x, ValueError) and str(x).startswith("field"):
            raise
        raise ValueError(f"malformed bias state: {x}") from None
    e.b, e.P, e.P0_inv, e.meat, e.clusters = b, P, P0_inv, meat, clusters
    e.n_clusters, e.rejected, e.t, e.used = counts["n_clusters"], counts["rejected"], t, used
    reg.pairs, reg.settled, reg._last = counts["pairs"], settled, last
