"""Saving and restoring a tracker: one ``.npz`` file, no pickle.

Layout (format ``mhtrack.mht.MHTTracker/3``): the leaf arrays as ``leaves__<column>``, the
birth process's as ``birth__<name>``, the tentative history's as ``history__<name>``, the
clutter estimator's ``get_state()`` arrays as ``clutter__<i>``, and ``meta``: one JSON
string with the format, the configuration, the estimator's name and state (arrays replaced
by ``{"__ndarray__": key}``), the last scan's time and index and the id counters.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from os import PathLike
from typing import Any

import numpy as np

from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.known import KnownClutter
from mhtrack.io.atomic import atomic_path
from mhtrack.mht.config import MHTConfig

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
            return arrays[obj["__ndarray__"]]
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


def load_state(path: str | PathLike[str], clutter: ClutterEstimator | None) -> SavedState:
    """Read a file written by :func:`save_state`. ``clutter`` is an estimator of the saved
    kind (its state is overwritten); it may be omitted for the ``known`` one."""
    with np.load(path, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}
    meta = json.loads(str(arrays.pop("meta")))
    if meta.get("format") != FORMAT:
        raise ValueError(f"{path}: not an MHT tracker state ({meta.get('format')!r})")
    if clutter is None:
        if meta["clutter_name"] != KnownClutter.name:
            raise ValueError(
                f"{path}: saved with clutter estimator {meta['clutter_name']!r}; "
                "pass one of that kind as clutter="
            )
        clutter = KnownClutter()
    elif clutter.name != meta["clutter_name"]:
        raise ValueError(
            f"{path}: saved with clutter estimator {meta['clutter_name']!r}, "
            f"got {clutter.name!r}"
        )
    clutter.set_state(decode(meta["clutter_state"], arrays))
    return SavedState(MHTConfig.from_json(json.dumps(meta["config"])), clutter, meta, arrays)
