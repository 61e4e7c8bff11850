"""Track continuity by Mode S address: a track that ends (the aircraft left coverage,
faded, or the tracker lost it) and is started again on plots with the same 24-bit ICAO
address keeps its id.

An ICAO address belongs to one airframe (ICAO Annex 10 vol. III; Mode S replies carry it
under a 24-bit parity), so a new track confirmed on plots of an address that a track
carried within the last :attr:`~mhtrack.mht.attribute_scores.AttributeModel.resume_s`
seconds, and that no current track carries, is that aircraft again: it takes the ended
track's id, the way surveillance trackers keep a track's identity through a gap (ours).
Tracks without an address are numbered as before (:func:`~mhtrack.mht.identity.confirm`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from mhtrack.mht.tree import Leaves


class AddressBook:
    """The last time (s) each track id was reported with a Mode S address."""

    def __init__(self, memory_s: float) -> None:
        self.memory_s = float(memory_s)
        self.track = np.zeros(0, np.int64)
        self.address = np.zeros(0, np.int64)
        self.time = np.zeros(0)

    def record(self, leaves: Leaves, reported: np.ndarray, time: float) -> None:
        """Remember the reported leaves' (mask) track ids and addresses at ``time``;
        forget entries older than the memory."""
        rows = (reported & (leaves.ident[:, 1] >= 0)).nonzero()[0]
        track = np.concatenate((leaves.track[rows], self.track))
        address = np.concatenate((leaves.ident[rows, 1], self.address))
        when = np.concatenate((np.full(rows.size, float(time)), self.time))
        track, first = np.unique(track, return_index=True)  # the newest entry per id
        keep = when[first] >= time - self.memory_s
        self.track, self.address, self.time = track[keep], address[first][keep], \
            when[first][keep]

    @staticmethod
    def one_per_address(leaves: Leaves, confirms: np.ndarray) -> np.ndarray:
        """``confirms`` without the tentative trees whose address a confirmed track of
        the best hypothesis carries: one confirmed track per Mode S address (the
        tentative tree may still take the id over when that track ends)."""
        on_air = leaves.chosen & (leaves.track >= 0) & (leaves.ident[:, 1] >= 0)
        if not on_air.any():
            return confirms
        taken = np.unique(leaves.ident[on_air, 1])
        clash = (leaves.track < 0) & (leaves.ident[:, 1] >= 0) & \
            np.isin(leaves.ident[:, 1], taken)
        return confirms & ~clash

    def resume(self, leaves: Leaves, confirms: np.ndarray
               ) -> tuple[Leaves, np.ndarray, np.ndarray]:
        """The tentative trees whose chosen leaf ``confirms`` (mask) and whose address an
        ended track (no leaf carries its id) had take that id — the most recently seen
        first, each id once, trees in order — before the others are numbered; returns
        the leaves, the ids resumed and the time each was last reported."""
        none = (leaves, np.zeros(0, np.int64), np.zeros(0))
        if self.track.size == 0:
            return none
        new = (leaves.chosen & (leaves.track < 0) & confirms).nonzero()[0]
        if new.size == 0:
            return none
        carried = np.unique(leaves.track[leaves.track >= 0])
        free = ~np.isin(self.track, carried)
        if not free.any():
            return none
        ids, addr, when = self.track[free], self.address[free], self.time[free]
        track = leaves.track.copy()
        taken: list[int] = []
        last: list[float] = []
        for r in new.tolist():
            a = int(leaves.ident[r, 1])
            hit = ((addr == a) & ~np.isin(ids, taken)).nonzero()[0] if a >= 0 else []
            if len(hit) == 0:
                continue
            k = hit[np.argmax(when[hit])]
            tid = int(ids[k])
            track[leaves.tree == leaves.tree[r]] = tid
            taken.append(tid)
            last.append(float(when[k]))
        if not taken:
            return none
        return replace(leaves, track=track), np.asarray(taken, np.int64), np.asarray(last)

    def arrays(self) -> dict[str, np.ndarray]:
        return {"track": self.track, "address": self.address, "time": self.time}

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """Restore :meth:`arrays` (an empty book when the state has none)."""
        if arrays:
            self.track = np.asarray(arrays["track"], np.int64)
            self.address = np.asarray(arrays["address"], np.int64)
            self.time = np.asarray(arrays["time"], float)
