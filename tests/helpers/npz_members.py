"""A saved state's members read and written back, for tests that edit state files."""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import numpy as np


def members(path: Path) -> dict[str, np.ndarray]:
    """Every member of the ``.npz`` at ``path`` (no pickles)."""
    with np.load(path, allow_pickle=False) as data:
        return {k: data[k] for k in data.files}


def write_members(path: Path, arrays: dict[str, np.ndarray], *,
                  allow_pickle: bool = False) -> Path:
    """``np.savez``'s layout with a fixed timestamp: the same bytes every run (so that
    byte-flipping examples are the same every run). ``allow_pickle``: object arrays may
    be written (a hostile state's)."""
    with zipfile.ZipFile(path, "w") as zf:
        for name, a in arrays.items():
            buf = io.BytesIO()
            np.lib.format.write_array(buf, np.asanyarray(a), allow_pickle=allow_pickle)
            zf.writestr(zipfile.ZipInfo(f"{name}.npy", date_time=(2020, 1, 1, 0, 0, 0)),
                        buf.getvalue())
    return path
