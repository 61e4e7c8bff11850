"""Saving and restoring a tracker: one ``.npz`` file, no pickle.

Layout (format ``mhtrack.mht.MHTTracker/3``): the leaf arrays as ``leaves__<column>``, the
birth process's as ``birth__<name>``, the tentative history's as ``history__<name>``, the
clutter estimator's ``get_state()`` arrays as ``clutter__<i>``, and ``meta``: one JSON
string with the format, the configuration, the estimator's name and state (arrays replaced
by ``{"__ndarray__": key}``), the last scan's time and index and the id counters.

:func:`load_state` reads nothing it has not checked: the archive's sizes and headers
(:func:`mhtrack.io.npzfile.read_npz`), then ``meta`` and every array
(:mod:`mhtrack.mht.state_checks`); each problem is one
:class:`~mhtrack.errors.InputError` line naming the file and the member or field.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from os import PathLike
from typing import Any

import numpy as np

from mhtrack.bounds import clip
from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.known import KnownClutter
from mhtrack.errors import InputError
from mhtrack.io.atomic import atomic_path
from mhtrack.io.npzfile import member_error, read_npz
from mhtrack.io.tomlfile import too_deep
from mhtrack.mht.config import MHTConfig
from mhtrack.mht.state_checks import check_arrays, check_meta

FORMAT = "mhtrack.mht.MHTTracker/3"


def encode(obj: Any, arrays: dict[str, np.ndarray]) -> Any:
    """JSON-able copy of ``obj`` with every ndarray moved into ``arrays``."""
    if isinstance(obj, np.ndarray):
        if obj.dtype.hasobject:
            raise ValueError("clutter state arrays must not hold Python objects")
        key = f"clutter__{len(arrays)}"
        arrays[key] = obj
        return {"__ndarray__": key}
    if isinstance(obj, dict):
        if not all(isinstance(k, str) for k in obj):
            raise ValueError("clutter state dict keys must be strings")
        return {k: encode(v, arrays) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [encode(v, arrays) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def decode(obj: Any, arrays: dict[str, np.ndarray]) -> Any:
    """Inverse of :func:`encode`."""
    if isinstance(obj, dict):
        if set(obj) == {"__ndarray__"}:
            key = obj["__ndarray__"]
            if not isinstance(key, str) or not key.startswith("clutter__") or key not in arrays:
                raise ValueError(f"field clutter_state: array {key!r} is not in the file")
            return arrays[key]
        return {k: decode(v, arrays) for k, v in obj.items()}
    if isinstance(obj, list):
        return [decode(v, arrays) for v in obj]
    return obj


def save_state(path: str | PathLike[str], parts: dict[str, dict[str, np.ndarray]],
               clutter: ClutterEstimator, config: MHTConfig, meta: dict[str, Any]) -> None:
    """Write ``parts`` (prefix → arrays, in order), the estimator's state, the
    configuration and ``meta`` (JSON-able bookkeeping) to ``path``, atomically."""
    arrays = {f"{prefix}__{k}": v for prefix, part in parts.items() for k, v in part.items()}
    clutter_state = encode(clutter.get_state(), arrays)
    meta = {"format": FORMAT, "config": json.loads(config.to_json()),
            "clutter_name": clutter.name, "clutter_state": clutter_state, **meta}
    arrays["meta"] = np.array(json.dumps(meta, sort_keys=True))
    with atomic_path(path, make_parent=False) as tmp, open(tmp, "wb") as f:
        np.savez(f, **arrays)  # type: ignore[arg-type]


@dataclass(frozen=True)
class SavedState:
    """What :func:`load_state` read: the configuration, the restored estimator, the JSON
    bookkeeping and the arrays."""

    config: MHTConfig
    clutter: ClutterEstimator
    meta: dict[str, Any]
    arrays: dict[str, np.ndarray]

    def part(self, prefix: str) -> dict[str, np.ndarray]:
        """The arrays saved under ``prefix`` (prefix removed)."""
        head = f"{prefix}__"
        return {k.removeprefix(head): v for k, v in self.arrays.items() if k.startswith(head)}


@contextmanager
def located(path: str | PathLike[str], member: str) -> Iterator[None]:
    """Turn an error raised while restoring ``member`` of the state file ``path`` into an
    :class:`InputError` naming both (a part's own ``set_arrays``/``set_state`` checks)."""
    try:
        yield
    except InputError:
        raise
    except (ValueError, TypeError, KeyError, IndexError, AttributeError,
            OverflowError) as e:
        what = f"missing {e}" if isinstance(e, KeyError) else str(e)
        raise member_error(path, member, f"cannot be restored ({what})") from None


def _meta(path: str | PathLike[str], arrays: dict[str, np.ndarray]) -> dict[str, Any]:
    raw = arrays.pop("meta", None)
    if raw is None:
        raise member_error(path, "meta", "missing (not an MHT tracker state)")
    if raw.dtype.kind != "U" or raw.shape != ():
        raise member_error(path, "meta", f"expected one JSON string, got {raw.dtype} "
                           f"{raw.shape}")
    try:
        meta = json.loads(str(raw))
    except (ValueError, RecursionError) as e:
        raise member_error(path, "meta", f"not JSON ({e})") from None
    if not isinstance(meta, dict):
        raise member_error(path, "meta", f"expected a JSON object, got {type(meta).__name__}")
    if too_deep(meta) is not None:
        raise member_error(path, "meta", "nested too deep")
    if meta.get("format") != FORMAT:
        raise member_error(path, "meta", f"not an MHT tracker state (format "
                           f"{meta.get('format')!r}, expected {FORMAT!r})")
    check_meta(path, meta)
    return meta


def saved_config(path: str | PathLike[str], meta: dict[str, Any]) -> MHTConfig:
    """The configuration of checked ``meta`` (its own checks as an :class:`InputError`)."""
    with located(path, "meta"):
        return MHTConfig.from_json(json.dumps(meta["config"]))


def saved_meta(path: str | PathLike[str]) -> dict[str, Any]:
    """The checked JSON bookkeeping of a state file (configuration, estimator name, and
    the builder's ``recipe`` when :func:`mhtrack.build.make_tracker` made the tracker),
    the configuration and the recipe included (:mod:`mhtrack.mht.state_checks`)."""
    meta = _meta(path, read_npz(path))
    saved_config(path, meta)
    return meta


def load_state(path: str | PathLike[str], clutter: ClutterEstimator | None) -> SavedState:
    """Read a file written by :func:`save_state`, checking it first (module docstring).
    ``clutter`` is an estimator of the saved kind (its state is overwritten); it may be
    omitted for the ``known`` one.

    Raises
    ------
    InputError : the file is not a valid state (one line naming the file and member).
    ValueError : ``clutter`` is not of the saved kind.
    """
    arrays = read_npz(path)
    meta = _meta(path, arrays)
    config = saved_config(path, meta)
    check_arrays(path, arrays, meta, config.n_scan)
    mu = arrays["leaves__mu"]
    with located(path, "meta"):
        n_models = config.motion.n_models
    if meta.get("recipe") is not None and mu.shape[1] != n_models:
        # the builder's trackers use the configuration's motion model
        raise member_error(path, "leaves__mu", f"{mu.shape[1]} IMM model probabilities per "
                           f"leaf, but the saved configuration's motion model has "
                           f"{n_models} models")
    if clutter is None:
        if meta["clutter_name"] != KnownClutter.name:
            raise ValueError(
                f"{path}: saved with clutter estimator {meta['clutter_name']!r}; "
                "pass one of that kind as clutter=, or load it with "
                "mhtrack.build.load_tracker (trackers made by make_tracker)"
            )
        clutter = KnownClutter()
    elif clutter.name != meta["clutter_name"]:  # an InputError is a ValueError too
        raise member_error(path, "meta", f"field 'clutter_name': saved with clutter "
                           f"estimator {clip(repr(meta['clutter_name']))}, got "
                           f"{clutter.name!r}")
    with located(path, "meta"):
        state = decode(meta.get("clutter_state"), arrays)
    with located(path, "clutter_state"):
        clutter.set_state(state)
    return SavedState(config, clutter, meta, arrays)
