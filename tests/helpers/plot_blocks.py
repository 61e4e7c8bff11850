"""CAT048 data blocks of known plots for the damaged-recording tests: ``n_blocks``
blocks of ``per_block`` plots each from one radar, plot ``i`` at ``i · dt`` s (block
``k`` holds plots ``k·per_block … (k+1)·per_block − 1``), ranges evenly from 10 km to
``max_range`` and bearings from 0 to 350°."""

from __future__ import annotations

import numpy as np

from mhtrack.io.asterix.encode import encode_blocks, plot_messages


def plot_blocks(n_blocks: int, per_block: int, *, dt: float = 0.5, sensor: int = 258,
                max_range: float = 2e5) -> list[bytes]:
    """The blocks (module docstring); one block per slice of plots, checked."""
    n = n_blocks * per_block
    msgs = plot_messages(np.arange(n) * dt, np.full(n, sensor), np.linspace(1e4, max_range, n),
                         np.linspace(0, 350, n), {})
    out = []
    for k in range(n_blocks):
        out += [b for _, _, b in encode_blocks(msgs[k * per_block:(k + 1) * per_block])]
    assert len(out) == n_blocks
    return out
