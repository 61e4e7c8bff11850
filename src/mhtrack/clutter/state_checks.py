"""Checks of a clutter estimator's saved state before it is restored (``set_state``).

A saved tracker (:mod:`mhtrack.mht.state`) carries its estimator's ``get_state()``; a
damaged or hostile one must fail when it is loaded, with the field named, never at a
later ``step`` (a broadcasting error from weights of the wrong length, an overflow from a
huge counter). Each function raises ``ValueError("<field>: <problem>")``, which the
state loader reports as one :class:`~mhtrack.errors.InputError` line naming the file and
``clutter_state``. Checked: types; every float finite and within ``±MAX_MAGNITUDE``
(a forgetting mixture's moment ``M_pq`` within ``M_00·(2·MAX_COORDINATE)^(p+q)``);
counters integers in ``[0, 2^53]``; positions within ``±MAX_COORDINATE``; a mixture's
``K`` the same in weights, means and covariances, weights in ``[0, 1]`` summing with the
background's to 1 (1e-6), covariances symmetric positive definite, a background box with
``x0 < x1``, ``y0 < y1``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from mhtrack.bounds import MAX_DENSITY, MAX_INDEX, MAX_MAGNITUDE, MAX_TIME_S, clip, show
from mhtrack.records import MAX_COORDINATE

#: Each forgetting-mixture moment column ``(p, q)``'s largest offset power
#: ``(2·MAX_COORDINATE)^(p+q)``: ``|M_pq| ≤ M_00 · d_max^(p+q)`` for weights ≥ 0.
_OFFSET_POWER = (2.0 * MAX_COORDINATE) ** np.array(
    [t for t in range(5) for _ in range(t + 1)], float)


def _fail(field: str, problem: str) -> ValueError:
    return ValueError(f"field {field}: {problem}")


def number(v: object, field: str, lo: float = -MAX_MAGNITUDE, hi: float = MAX_MAGNITUDE,
           *, integer: bool = False) -> float:
    """``v`` as a finite number (an integer when ``integer``) in ``[lo, hi]``."""
    ok = isinstance(v, int) if integer else isinstance(v, int | float)
    if isinstance(v, bool) or not ok:
        raise _fail(field, f"expected {'an integer' if integer else 'a number'}, got "
                    f"{type(v).__name__}")
    if not lo <= v <= hi:  # false for NaN
        raise _fail(field, f"{clip(repr(v))} is out of range [{show(lo)}, {show(hi)}]")
    return v  # type: ignore[return-value]


def array(v: object, field: str, shape: tuple[int, ...], *, kind: str = "f",
          bound: float = MAX_MAGNITUDE) -> np.ndarray:
    """``v`` as an array of ``shape`` (``-1``: any length) of numbers (``kind`` ``"f"``
    finite floats, ``"i"`` integers), every value within ``±bound``."""
    if isinstance(v, np.ndarray):
        a = v
    elif isinstance(v, list):
        try:
            a = np.asarray(v)
        except (TypeError, ValueError, OverflowError):
            raise _fail(field, "expected numbers") from None
        if a.size == 0:
            a = a.astype(np.int64 if kind == "i" else float)
    else:
        raise _fail(field, f"expected an array, got {type(v).__name__}")
    if a.dtype.kind not in ("biu" if kind == "i" else "biuf") or a.dtype.kind == "b":
        raise _fail(field, f"expected {'integers' if kind == 'i' else 'numbers'}, got {a.dtype}")
    if a.ndim != len(shape) or any(s not in (-1, n) for s, n in zip(shape, a.shape, strict=True)):
        raise _fail(field, f"has shape {a.shape}, expected {shape}")
    if a.size and not (np.abs(a.astype(float)) <= bound).all():  # false for NaN
        raise _fail(field, f"holds values that are not finite or beyond ±{bound:g}")
    return a


def check_known(state: Mapping[str, Any]) -> float:
    """The known estimator's ``kappa`` (per m²), finite in ``(0, MAX_DENSITY]``."""
    kappa = number(state["kappa"], "clutter_state.kappa", 0.0, MAX_DENSITY)
    if kappa <= 0:
        raise _fail("clutter_state.kappa", f"must be > 0, got {kappa!r}")
    return float(kappa)


def check_mixture(m: Mapping[str, Any], field: str = "clutter_state.mixture") -> None:
    """A :class:`~mhtrack.clutter.density.Mixture` state (``to_state``)."""
    w = array(m["weights"], f"{field}.weights", (-1,))
    k = len(w)
    means = array(m["means"], f"{field}.means", (k, 2), bound=MAX_COORDINATE)
    cov = array(m["covariances"], f"{field}.covariances", (k, 2, 2))
    del means
    bg = number(m["background_weight"], f"{field}.background_weight", 0.0, 1.0)
    if (w < 0).any() or (w > 1).any() or abs(float(w.sum()) + bg - 1.0) > 1e-6:
        raise _fail(f"{field}.weights", "must be in [0, 1] and sum to 1 with the "
                    "background's")
    a, b, c, d = cov[:, 0, 0], cov[:, 0, 1], cov[:, 1, 0], cov[:, 1, 1]
    bad = ~((b == c) & (a > 0) & (a * d - b * c > 0))
    if bad.any():
        raise _fail(f"{field}.covariances", f"matrix {int(np.argmax(bad))} is not symmetric "
                    "positive definite")
    box = m["background_box"]
    if box is not None:
        x0, x1, y0, y1 = array(box, f"{field}.background_box", (4,), bound=MAX_COORDINATE)
        if not (x0 < x1 and y0 < y1):
            raise _fail(f"{field}.background_box", "expected x0 < x1 and y0 < y1")
    elif bg > 0:
        raise _fail(f"{field}.background_weight", "is > 0 without a background box")


def check_mixture_estimator(state: Mapping[str, Any]) -> None:
    """A GMM/AGMM estimator's state (:meth:`MixtureClutter.get_state`)."""
    f = "clutter_state"
    if not isinstance(state["window"], list):
        raise _fail(f"{f}.window", "expected a list of scans")
    for i, w in enumerate(state["window"]):
        z = array(w, f"{f}.window[{i}]", (-1,) * np.ndim(w), bound=MAX_COORDINATE)
        if z.size % 2:
            raise _fail(f"{f}.window[{i}]", "expected (n, 2) positions")
    if "kept" in state:
        array(state["kept"], f"{f}.kept", (-1,) * np.ndim(state["kept"]), kind="i",
              bound=MAX_INDEX)
    if state["mixture"] is not None:
        if not isinstance(state["mixture"], dict):
            raise _fail(f"{f}.mixture", "expected an object or null")
        check_mixture(state["mixture"])
    number(state["count"], f"{f}.count", 0.0)
    for key in ("n_iter", "n_pruned", "n_updates", "n_subsampled"):
        number(state[key], f"{f}.{key}", 0, MAX_INDEX, integer=True)
    if not isinstance(state["converged"], bool):
        raise _fail(f"{f}.converged", "expected true or false")
    if state["log_likelihood"] is not None:
        number(state["log_likelihood"], f"{f}.log_likelihood")


def check_scan(d: Mapping[str, Any], field: str) -> None:
    """A pending scan of the per-radar estimator."""
    number(d["index"], f"{field}.index", -MAX_INDEX, MAX_INDEX, integer=True)
    number(d["time"], f"{field}.time", -MAX_TIME_S, MAX_TIME_S)
    z = array(d["z"], f"{field}.z", (-1,) * np.ndim(d["z"]), bound=MAX_COORDINATE)
    n = z.size // 2
    if z.size % 2:
        raise _fail(f"{field}.z", "expected (n, 2) positions")
    for key in ("sensor", "rows"):
        array(d[key], f"{field}.{key}", (n,), kind="i", bound=MAX_INDEX)
    t = array(d["t"], f"{field}.t", (n,), bound=MAX_TIME_S)
    if n and (t > d["time"]).any():
        raise _fail(f"{field}.t", "plot times after the scan's time")


def check_map(state: Mapping[str, Any], n_azimuth: int, max_rings: int, gamma: float
              ) -> tuple[np.ndarray, float, np.ndarray, float | None]:
    """A clutter map's state (:meth:`ClutterMap.get_state`): ``sums`` (rings, ``n_azimuth``)
    with at most ``max_rings`` rings, each ≥ 0; ``looks`` in ``[0, 1/(1 − γ)]`` (at most
    ``MAX_INDEX`` for ``γ = 1``); ``last`` flat cells in ``[−1, cells)``; ``time`` (the
    last rotation's, absent or null before one) finite."""
    f = "clutter_state"
    sums = array(state["sums"], f"{f}.sums", (-1, n_azimuth)).astype(float)
    if sums.shape[0] > max_rings:
        raise _fail(f"{f}.sums", f"has {sums.shape[0]} rings, more than {max_rings}")
    if (sums < 0).any():
        raise _fail(f"{f}.sums", "holds negative counts")
    top = float(MAX_INDEX) if gamma >= 1.0 else 1.0 / (1.0 - gamma) + 1e-9
    looks = float(number(state["looks"], f"{f}.looks", 0.0, top))
    number(state["n_updates"], f"{f}.n_updates", 0, MAX_INDEX, integer=True)
    number(state["n_outside"], f"{f}.n_outside", 0, MAX_INDEX, integer=True)
    last = array(state["last"], f"{f}.last", (-1,), kind="i", bound=MAX_INDEX).astype(np.int64)
    if last.size and (last.min() < -1 or last.max() >= sums.size):
        raise _fail(f"{f}.last", f"cells must be in [-1, {sums.size})")
    t = state.get("time")
    t = None if t is None else float(number(t, f"{f}.time", -MAX_TIME_S, MAX_TIME_S))
    return np.ascontiguousarray(sums), looks, last, t


def check_forgetting(state: Mapping[str, Any], max_components: int, gamma: float
                     ) -> tuple[np.ndarray, np.ndarray, Any, Any]:
    """A forgetting mixture's state (:meth:`ForgettingGMMClutter.get_state`): at most
    ``max_components`` rows of 15 moments and 2 anchor coordinates, each weight ``M_00`` > 0
    with a positive definite covariance; masses, counts ≥ 0; ``looks`` in
    ``[0, 1/(1 − γ)]``; a box with ``x0 < x1``, ``y0 < y1`` or null."""
    from mhtrack.clutter.moments import mean_cov

    f = "clutter_state"
    # M_pq = Σ w dx^p dy^q: |M_pq| ≤ M_00 · d_max^(p+q), with d_max ≤ 2·MAX_COORDINATE, per
    # row; a fixed ±MAX_MAGNITUDE bound refused every real radar's fourth moments (σ 50 km:
    # 3σ⁴ ≈ 2·10¹⁹ per unit weight).
    m = array(state["moments"], f"{f}.moments", (-1, 15), bound=np.inf).astype(float)
    if m.size and not (np.abs(m[:, 0]) <= MAX_MAGNITUDE).all():  # false for NaN
        raise _fail(f"{f}.moments", f"a weight M_00 not finite or beyond ±{MAX_MAGNITUDE:g}")
    if m.size and not (m[:, 0] > 0).all():
        raise _fail(f"{f}.moments", "a component has no weight")
    if m.size and not (np.abs(m) <= m[:, :1] * _OFFSET_POWER).all():  # false for NaN
        raise _fail(f"{f}.moments", "holds values that are not finite or beyond "
                    "M_00·(2·MAX_COORDINATE)^(p+q)")
    a = array(state["anchors"], f"{f}.anchors", (len(m), 2), bound=MAX_COORDINATE)
    if len(m) > max_components:
        raise _fail(f"{f}.moments", f"{len(m)} components, more than {max_components}")
    if len(m):
        _, _, cov = mean_cov(m, a.astype(float), 0.0)
        det = cov[:, 0, 0] * cov[:, 1, 1] - cov[:, 0, 1] ** 2
        if not (np.isfinite(det).all() and (cov[:, 0, 0] > 0).all() and (det > 0).all()):
            raise _fail(f"{f}.moments", "a component's covariance is not positive definite")
    number(state["bg_mass"], f"{f}.bg_mass", 0.0)
    number(state["count_sum"], f"{f}.count_sum", 0.0)
    top = float(MAX_INDEX) if gamma >= 1.0 else 1.0 / (1.0 - gamma) + 1e-9
    number(state["looks"], f"{f}.looks", 0.0, top)
    number(state["n_updates"], f"{f}.n_updates", 0, MAX_INDEX, integer=True)
    boxes = []
    for key in ("box", "extent"):
        box = state[key]
        if box is not None:
            x0, x1, y0, y1 = (float(v) for v in array(box, f"{f}.{key}", (4,),
                                                      bound=MAX_COORDINATE))
            if not (x0 <= x1 and y0 <= y1) or (key == "box" and not (x0 < x1 and y0 < y1)):
                raise _fail(f"{f}.{key}", "expected x0 < x1 and y0 < y1")
            box = (x0, x1, y0, y1)
        boxes.append(box)
    return np.ascontiguousarray(m), np.ascontiguousarray(a, dtype=float), boxes[0], boxes[1]
