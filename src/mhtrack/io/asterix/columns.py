"""Decoded report rows as typed column arrays, in the layout of CAT048 plots
(:data:`mhtrack.io.asterix.decode.PLOT_COLUMNS`) and the columns the other categories add
(``plot_type``, the flags, ADS-B's ``lat, lon, sigma``): floats NaN where absent, integers
``-1``, text ``""`` (docs/file-formats.md, "ASTERIX recordings")."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

#: The dtype of every column name the readers produce.
KINDS: dict[str, Any] = {
    "time": float, "sensor": np.int64, "sac": np.int64, "sic": np.int64,
    "slant_range": float, "bearing": float, "flight_level": float, "mode_3a": object,
    "address": object, "callsign": object, "track_number": np.int64, "typ": np.int64,
    "plot_type": np.int64, "sim": np.int64, "rab": np.int64, "tst": np.int64,
    "track": np.int64, "lat": float, "lon": float, "sigma": float,
    "mode_3a_vg": np.int64, "flight_level_vg": np.int64}


def columns(rows: Sequence[tuple[Any, ...]], names: Sequence[str]
            ) -> dict[str, np.ndarray]:
    """``{name: array}`` of row tuples whose fields are ``names`` (each a :data:`KINDS`
    key); empty arrays of the right dtypes when there is no row."""
    cols = list(zip(*rows, strict=True)) if rows else [()] * len(names)
    return {name: np.array(c, dtype=KINDS[name]) for name, c in zip(names, cols,
                                                                    strict=True)}
