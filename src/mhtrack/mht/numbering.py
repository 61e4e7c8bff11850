"""Ids that are consecutive and never reused: trees, track ids and leaf nodes."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from mhtrack.mht.tree import Leaves


class Counter:
    """The next free id of one kind; :meth:`take` reserves ``n`` consecutive ids."""

    def __init__(self, start: int = 0) -> None:
        self.next = int(start)

    def take(self, n: int) -> int:
        """Reserve ids ``first … first + n − 1`` and return ``first``."""
        first = self.next
        self.next += int(n)
        return first


def number_nodes(leaves: Leaves, nodes: Counter) -> Leaves:
    """Give every leaf of the scan a new node id, ascending in row order (the links of
    :mod:`mhtrack.mht.history`)."""
    first = nodes.take(len(leaves))
    return replace(leaves, node=np.arange(first, first + len(leaves), dtype=np.int64))
