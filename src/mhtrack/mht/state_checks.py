"""Checks of a saved tracker state before it is restored (:mod:`mhtrack.mht.state`).

Every problem is one :class:`~mhtrack.errors.InputError` line naming the file and the
member (array) or the ``meta`` field: ``state.npz, member 'leaves__P': row 3 is not
symmetric positive definite (Cholesky fails)``. Checked: the bookkeeping numbers of
``meta`` (types and :mod:`mhtrack.bounds`), every leaf and history column's dtype kind and
shape (all columns of one part the same length; ``window`` as wide as ``n_scan + 1``;
IMM axes consistent), finiteness of every float, covariances symmetric (to 1e-9
relative) and positive definite (Cholesky succeeds), model probabilities in [0, 1]
summing to 1, and the counts: leaves sorted by tree, ids below the saved counters.
"""

from __future__ import annotations

from collections.abc import Mapping
from os import PathLike
from typing import Any

import numpy as np

from mhtrack.bounds import (
    MAX_DENSITY,
    MAX_INDEX,
    MAX_TIME_S,
    clip,
    float_problem,
    int_problem,
)
from mhtrack.io.npzfile import member_error
from mhtrack.names import CLUTTER_FRAMES, TRACKERS

PathArg = str | PathLike[str]

#: Leaf columns: (dtype kinds, trailing shape; "w" = window width, "r" = IMM models).
LEAF_COLUMNS: dict[str, tuple[str, tuple[Any, ...]]] = {
    "x": ("f", (4,)), "P": ("f", (4, 4)), "score": ("f", ()), "peak": ("f", ()),
    "tree": ("iu", ()), "track": ("iu", ()), "birth": ("iu", ()), "n_updates": ("iu", ()),
    "window": ("iu", ("w",)), "chosen": ("b", ()), "mu": ("f", ("r",)),
    "xm": ("f", ("r", 4)), "Pm": ("f", ("r", 4, 4)), "node": ("iu", ()),
    "parent": ("iu", ()), "time": ("f", ()), "level": ("fn", (7,)), "ident": ("iu", (2,)),
}
#: Columns of the address book (``addresses__<name>``, :mod:`mhtrack.mht.resume`).
ADDRESS_COLUMNS: dict[str, tuple[str, tuple[Any, ...]]] = {
    "track": ("iu", ()), "address": ("iu", ()), "time": ("f", ()),
}
#: Columns of the callsigns (``callsigns__<name>``, :mod:`mhtrack.mht.track_attributes`).
CALLSIGN_COLUMNS: dict[str, tuple[str, tuple[Any, ...]]] = {
    "track": ("iu", ()), "callsign": ("U", ()), "time": ("f", ()),
}
#: Columns of the sensors' last updates (``ages__<name>``, :mod:`mhtrack.mht.sensor_ages`).
AGE_COLUMNS: dict[str, tuple[str, tuple[Any, ...]]] = {
    "track": ("iu", ()), "sensor": ("iu", ()), "time": ("f", ()),
}
#: Columns of one logged scan of the tentative history (``history__<i>__<name>``).
HISTORY_COLUMNS: dict[str, tuple[str, tuple[Any, ...]]] = {
    "node": ("iu", ()), "parent": ("iu", ()), "x": ("f", (4,)), "P": ("f", (4, 4)),
    "plot": ("iu", ()), "score": ("f", ()), "t": ("f", ()), "ident": ("iu", (2,)),
    "level": ("fn", (7,)),
}
#: Relative tolerance of the symmetry of a covariance.
SYMMETRY_RTOL = 1e-9


class _Checker:
    def __init__(self, path: PathArg, arrays: Mapping[str, np.ndarray]) -> None:
        self.path = path
        self.arrays = arrays

    def fail(self, member: str, problem: str) -> Exception:
        return member_error(self.path, member, problem)

    def column(self, member: str, kinds: str, shape: tuple[int, ...]) -> np.ndarray:
        """The array ``member``: present, of a dtype kind in ``kinds`` and shape ``shape``
        (``-1`` = any length), floats finite (kinds ``"fn"``: NaN allowed, as "none")."""
        if member not in self.arrays:
            raise self.fail(member, "missing")
        a = self.arrays[member]
        if a.dtype.kind not in kinds:
            want = {"f": "floats", "iu": "integers", "b": "booleans"}.get(kinds, kinds)
            raise self.fail(member, f"has dtype {a.dtype}, expected {want}")
        if a.ndim != len(shape) or any(s not in (-1, n) for s, n in
                                       zip(shape, a.shape, strict=True)):
            want_shape = "(" + ", ".join("n" if s == -1 else str(s) for s in shape) + ")"
            raise self.fail(member, f"has shape {a.shape}, expected {want_shape}")
        if a.dtype.kind == "f":
            bad = np.isinf(a) if "n" in kinds else ~np.isfinite(a)
            if bad.any():
                i = np.argwhere(bad)[0]
                raise self.fail(member, f"value {a[tuple(i)].item()!r} at index "
                                f"{tuple(i.tolist())} is not finite")
        if a.dtype.kind in "iu" and a.size and (np.abs(a.astype(np.float64)) > MAX_INDEX).any():
            raise self.fail(member, f"holds integers beyond ±2^53 (max {a.max()})")
        return a

    def part(self, prefix: str, columns: Mapping[str, tuple[str, tuple[Any, ...]]],
             sizes: Mapping[str, int], optional: tuple[str, ...] = ()) -> dict[str, np.ndarray]:
        """Every column of a part, all with one row count; ``sizes`` fixes the named
        trailing axes (a missing one is taken from the first column that has it)."""
        sizes = dict(sizes)
        n = None
        out = {}
        for name, (kinds, tail) in columns.items():
            member = f"{prefix}{name}"
            if name in optional and member not in self.arrays:
                continue
            a = self.arrays.get(member)
            shape = []
            for j, s in enumerate(tail):
                if isinstance(s, str) and s not in sizes and a is not None and a.ndim > j + 1:
                    sizes[s] = int(a.shape[j + 1])
                shape.append(sizes.get(s, -1) if isinstance(s, str) else s)
            out[name] = self.column(member, kinds, (-1 if n is None else n, *shape))
            n = out[name].shape[0] if n is None else n
        return out

    def covariances(self, member: str, P: np.ndarray) -> None:
        """Each matrix of ``P`` (…, d, d) symmetric and positive definite."""
        flat = P.reshape(-1, *P.shape[-2:])
        scale = np.abs(flat).max(axis=(1, 2)) + np.finfo(float).tiny
        asym = np.abs(flat - flat.transpose(0, 2, 1)).max(axis=(1, 2)) > SYMMETRY_RTOL * scale
        if asym.any():
            raise self.fail(member, f"matrix {int(np.argmax(asym))} is not symmetric")
        try:
            np.linalg.cholesky(flat)
        except np.linalg.LinAlgError:
            for i, m in enumerate(flat):
                try:
                    np.linalg.cholesky(m)
                except np.linalg.LinAlgError:
                    raise self.fail(member, f"matrix {i} is not positive definite (Cholesky "
                                    "fails)") from None


def _meta_number(path: PathArg, meta: Mapping[str, Any], key: str, *, integer: bool,
                 lo: float, hi: float, nullable: bool = False) -> None:
    v = meta.get(key)
    if v is None and nullable:
        return
    ok = (isinstance(v, int) if integer else isinstance(v, int | float)) and not isinstance(
        v, bool) and lo <= v <= hi  # NaN compares false
    if not ok:
        what = "an integer" if integer else "a finite number"
        raise member_error(path, "meta", f"field {key!r}: expected {what} in [{lo:g}, "
                           f"{hi:g}]{' or null' if nullable else ''}, got {v!r}")


def _config_numbers(path: PathArg, config: Mapping[str, Any]) -> None:
    """Every number of the saved configuration within :mod:`mhtrack.bounds` (``±1e15``,
    integers ``±2^53``), so that no later square or exponential overflows; the
    configuration's own checks (``MHTConfig``) follow."""
    for key, v in config.items():
        if isinstance(v, bool) or not isinstance(v, int | float):
            continue
        problem = (int_problem(v) if isinstance(v, int) else float_problem(v))
        if problem is not None:
            raise member_error(path, "meta", f"field 'config.{key}': {problem}")


def _recipe(path: PathArg, recipe: object) -> None:
    """The builder's recipe (:func:`mhtrack.build.make_tracker`): its names, numbers and
    radars, so that rebuilding the tracker from it cannot fail."""
    if recipe is None:
        return

    def fail(key: str, problem: str) -> Exception:
        return member_error(path, "meta", f"field 'recipe.{key}': {problem}")

    if not isinstance(recipe, dict):
        raise member_error(path, "meta", f"field 'recipe': expected an object, got "
                           f"{type(recipe).__name__}")
    if recipe.get("name") not in TRACKERS:
        raise fail("name", f"expected one of {', '.join(TRACKERS)}, got "
                   f"{clip(repr(recipe.get('name')))}")
    kappa = recipe.get("clutter_density")
    if kappa is not None and (problem := float_problem(kappa, 0.0, MAX_DENSITY,
                                                        lo_open=True)) is not None:
        raise fail("clutter_density", problem)
    if recipe.get("clutter_frame", "polar") not in CLUTTER_FRAMES:
        raise fail("clutter_frame", f"expected one of {', '.join(CLUTTER_FRAMES)}")
    params = recipe.get("clutter_params")
    if params is not None and not (isinstance(params, dict) and all(
            isinstance(v, bool | int | float | str) or v is None for v in params.values())):
        raise fail("clutter_params", "expected an object of names and plain values")
    if params:
        _config_numbers(path, {f"recipe.clutter_params.{k}": v for k, v in params.items()})
        from mhtrack.clutter import AGMMClutter, GMMClutter

        # the builder passes them to its mixture estimator (None: the default)
        cls = {"mht-gmm": GMMClutter, "mht-agmm": AGMMClutter}.get(recipe["name"])
        if cls is not None:
            try:
                cls(**{k: v for k, v in params.items() if v is not None})
            except (TypeError, ValueError, OverflowError) as e:
                raise fail("clutter_params", clip(str(e), 120)) from None
    sensors = recipe.get("sensors")
    if sensors is not None:
        from mhtrack.models.radars import RadarSensor, SensorSet

        origin = sensors.get("origin") if isinstance(sensors, dict) else None
        if origin is not None and not (isinstance(origin, list) and len(origin) == 2 and all(
                isinstance(v, int | float) and not isinstance(v, bool) for v in origin)):
            raise fail("sensors.origin", "expected null or [lat, lon], two numbers, got "
                       f"{clip(repr(origin))}")
        try:
            origin = sensors["origin"]
            SensorSet(None if origin is None else (float(origin[0]), float(origin[1])),
                      tuple(RadarSensor(**{k: (tuple(v) if isinstance(v, list) else v)
                                           for k, v in d.items()})
                            for d in sensors["sensors"]))
        except (ValueError, TypeError, KeyError, IndexError, AttributeError,
                OverflowError) as e:
            raise fail("sensors", f"not a set of radars ({clip(str(e), 120)})") from None


def check_meta(path: PathArg, meta: Mapping[str, Any]) -> None:
    """The bookkeeping numbers and names of ``meta`` (every key present)."""
    for key in ("next_tree", "next_track", "next_node", "last_index", "last_time",
                "clutter_name", "config"):
        if key not in meta:
            raise member_error(path, "meta", f"field {key!r}: missing")
    for key in ("next_tree", "next_track", "next_node"):
        _meta_number(path, meta, key, integer=True, lo=0, hi=MAX_INDEX)
    _meta_number(path, meta, "last_index", integer=True, lo=-MAX_INDEX, hi=MAX_INDEX,
                 nullable=True)
    _meta_number(path, meta, "last_time", integer=False, lo=-MAX_TIME_S, hi=MAX_TIME_S,
                 nullable=True)
    for key in ("clutter_name",):
        if not isinstance(meta.get(key), str):
            raise member_error(path, "meta", f"field {key!r}: expected a string, got "
                               f"{meta.get(key)!r}")
    if not isinstance(meta.get("config"), dict):
        raise member_error(path, "meta", "field 'config': expected an object")
    _config_numbers(path, meta["config"])
    _recipe(path, meta.get("recipe"))


def check_arrays(path: PathArg, arrays: Mapping[str, np.ndarray], meta: Mapping[str, Any],
                 n_scan: int) -> None:
    """The leaf and history arrays (module docstring)."""
    c = _Checker(path, arrays)
    leaves = c.part("leaves__", LEAF_COLUMNS, {"w": n_scan + 1},
                    optional=("level", "ident"))
    c.covariances("leaves__P", leaves["P"])
    if leaves["Pm"].size:
        c.covariances("leaves__Pm", leaves["Pm"])
    mu = leaves["mu"]
    if mu.shape[1] and ((mu < 0).any() or (mu > 1).any()
                        or (np.abs(mu.sum(axis=1) - 1) > 1e-6).any()):
        raise c.fail("leaves__mu", "model probabilities must be in [0, 1] and sum to 1")
    tree = leaves["tree"]
    if tree.size > 1 and (tree[1:] < tree[:-1]).any():
        raise c.fail("leaves__tree", "leaves are not sorted by tree")
    for name, lo, counter in (("tree", 0, "next_tree"), ("track", -1, "next_track"),
                              ("node", -1, "next_node"), ("parent", -1, "next_node")):
        v = leaves[name]
        if v.size and (v.min() < lo or v.max() >= meta[counter]):
            raise c.fail(f"leaves__{name}", f"ids must be in [{lo}, {meta[counter]}) (the "
                         f"saved {counter}), got {v.min()} to {v.max()}")
    t = leaves["time"]
    last = meta["last_time"]
    if t.size and (np.abs(t).max() > MAX_TIME_S or (
            last is not None and t.max() > last)):
        raise c.fail("leaves__time", f"leaf times must be within ±{MAX_TIME_S:g} s and not "
                     f"after the last scan's time ({last} s)")
    for name in ("n_updates", "birth"):
        if leaves[name].size and leaves[name].min() < 0:
            raise c.fail(f"leaves__{name}", "must be >= 0")
    if leaves["window"].size and leaves["window"].min() < -1:
        raise c.fail("leaves__window", "plot rows must be >= -1")
    if any(k.startswith("addresses__") for k in arrays):  # mht/resume.AddressBook
        book = c.part("addresses__", ADDRESS_COLUMNS, {})
        v = book["track"]
        if v.size and (v.min() < 0 or v.max() >= meta["next_track"]):
            raise c.fail("addresses__track", f"ids must be in [0, {meta['next_track']}) "
                         f"(the saved next_track), got {v.min()} to {v.max()}")
    for part, columns in (("callsigns", CALLSIGN_COLUMNS), ("ages", AGE_COLUMNS)):
        if not any(k.startswith(f"{part}__") for k in arrays):  # mht/track_attributes
            continue
        v = c.part(f"{part}__", columns, {})["track"]
        if v.size and (v.min() < 0 or v.max() >= meta["next_track"]):
            raise c.fail(f"{part}__track", f"ids must be in [0, {meta['next_track']}) "
                         f"(the saved next_track), got {v.min()} to {v.max()}")
    if "history__count" not in arrays:
        return
    count = c.column("history__count", "iu", (1,))
    n_logged = int(count[0])
    if not 0 <= n_logged <= len(arrays):
        raise c.fail("history__count", f"{n_logged} logged scans, but the file does not "
                     "hold that many")
    for i in range(n_logged):
        prefix = f"history__{i}__"
        c.column(f"{prefix}scan", "iu", (1,))
        c.column(f"{prefix}time", "f", (1,))
        log = c.part(prefix, HISTORY_COLUMNS, {}, optional=("t", "ident", "level"))
        c.covariances(f"{prefix}P", log["P"])
        c.column(f"{prefix}claimed", "iu", (-1,))
