"""The tentative past of newly confirmed tracks (the *backfill*).

An MHT confirms a track only once its score passes the SPRT threshold, a few scans after
the target's first plot; until then the track is a tentative branch of its tree. A batch
user wants the track from its first plot (as Stone Soup's multi-measurement initiator
releases a track with its states since the first plot). This module keeps, for the last
``depth`` scans, the state of every tentative leaf and the id of the leaf it grew from
(``Leaves.node``, ``Leaves.parent``); when a tree is confirmed at scan ``k``, its chosen
leaf's ancestors give the track's states at the scans before ``k`` — exactly the filtered
states, plots and scores of the branch the confirmation decided on.

Backfilled rows are *tentative*: at their scans the tracker had not yet decided that the
track is a target. :attr:`mhtrack.records.TrackTable.tentative` marks them, so the online
view (``tentative == 0``) is always recoverable from a history output.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, fields

import numpy as np

from mhtrack.mht.tree import Leaves
from mhtrack.records import TrackTable


@dataclass(frozen=True, slots=True)
class _Logged:
    """Tentative leaves after one scan, sorted by ``node``."""

    scan: np.ndarray  # (1,) scan index
    time: np.ndarray  # (1,) scan time
    node: np.ndarray
    parent: np.ndarray
    x: np.ndarray
    P: np.ndarray
    plot: np.ndarray
    score: np.ndarray

    @classmethod
    def of(cls, scan: int, time: float, leaves: Leaves) -> _Logged:
        sel = np.flatnonzero(leaves.track < 0)
        node = leaves.node[sel]
        if node.size > 1 and (np.diff(node) <= 0).any():
            sel = sel[np.argsort(node, kind="stable")]
            node = leaves.node[sel]
        return cls(np.array([scan], np.int64), np.array([time], float), node,
                   leaves.parent[sel], leaves.x[sel], leaves.P[sel], leaves.window[sel, -1],
                   leaves.score[sel])


class TentativeHistory:
    """States of tentative leaves over the last ``depth`` scans (0: keep nothing).

    Call :meth:`record` once per scan after the track management, and :meth:`backfill`
    before it for the leaves confirmed at that scan.
    """

    def __init__(self, depth: int) -> None:
        if depth < 0:
            raise ValueError(f"history depth must be >= 0, got {depth}")
        self.depth = int(depth)
        self._log: deque[_Logged] = deque(maxlen=max(self.depth, 1))

    def record(self, scan: int, time: float, leaves: Leaves) -> None:
        """Keep the tentative leaves (``track < 0``) of this scan."""
        if self.depth:
            self._log.append(_Logged.of(scan, time, leaves))

    def backfill(self, leaves: Leaves, rows: np.ndarray) -> TrackTable:
        """The ancestors of leaves ``rows`` (just confirmed, ``track >= 0``) at the logged
        scans, as track rows with their track ids, ordered by scan then track id, all
        marked tentative. Walks each parent link one logged scan back at a time; a chain
        ends at its tree's root or at the oldest logged scan."""
        rows = np.asarray(rows, np.int64)
        if not self.depth or rows.size == 0 or not self._log:
            return TrackTable.empty()
        cur = leaves.parent[rows]
        tid = leaves.track[rows]
        parts: list[TrackTable] = []
        for log in reversed(self._log):
            if cur.size == 0 or log.node.size == 0:
                break  # every chain has ended (an ancestor is logged at every scan)
            j = np.minimum(np.searchsorted(log.node, cur), log.node.size - 1)
            found = log.node[j] == cur
            j, tid = j[found], tid[found]
            x = log.x[j]
            n = j.size
            parts.append(TrackTable(
                scan=np.repeat(log.scan, n), time=np.repeat(log.time, n), track_id=tid,
                x=x[:, 0].copy(), y=x[:, 2].copy(), vx=x[:, 1].copy(), vy=x[:, 3].copy(),
                plot=log.plot[j], score=log.score[j], P=log.P[j],
                tentative=np.ones(n, bool)))
            cur = log.parent[j]
            live = cur >= 0
            cur, tid = cur[live], tid[live]
        parts.reverse()
        out = TrackTable.concat(parts)
        if len(out) == 0:
            return TrackTable.empty()
        return out.sorted()

    # ------------------------------------------------------------- persistence
    def arrays(self) -> dict[str, np.ndarray]:
        """The log as flat arrays (for :meth:`MHTTracker.save`)."""
        out: dict[str, np.ndarray] = {"count": np.array([len(self._log)], np.int64)}
        for i, log in enumerate(self._log):
            for f in fields(_Logged):
                out[f"{i}__{f.name}"] = getattr(log, f.name)
        return out

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """Restore what :meth:`arrays` wrote."""
        self._log.clear()
        for i in range(int(arrays["count"][0]) if "count" in arrays else 0):
            self._log.append(_Logged(**{f.name: np.asarray(arrays[f"{i}__{f.name}"])
                                        for f in fields(_Logged)}))
