"""A bounded re-order buffer: plots that arrive slightly out of time order leave in time
order; plots that arrive too late to be put in order are dropped and counted.

Rule (``docs/sources.md``, *Ordering*): with ``M`` the latest plot time seen so far and
``W`` the window (s), a plot is held until ``M − t > W``, then released; held plots leave
in time order, ties in arrival order. A plot whose time is before the last time already
released cannot be put in order: it is dropped, counted, and its lateness ``M − t``
recorded. A plot at most ``W`` older than ``M`` is therefore never dropped. Rows with
``mark`` true (a radar's sweep marks — CAT034/CAT002 north markers and sector crossings,
:mod:`mhtrack.sources.marks`) follow the same rule but are no plots: a late one is
dropped and counted apart (:attr:`ReorderBuffer.late_marks`), never as a late plot.

This is the one rule for every reader of timed plots: the sources (``track``, ``live``)
push their plots through the buffer as they come, and
:func:`mhtrack.io.timed_plots.read_timed_plots` (``read_plots``, ``evaluate --plots``)
replays it on a whole file (:func:`kept`), so that both keep and drop the same rows, with
the same warning line (:meth:`Late.line`).

The buffer holds the plots of the last ``W`` seconds of the stream (plus the current
batch), never the whole input.
"""

from __future__ import annotations

import heapq
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

#: Plots may come out of time order by this much (s) by default (network jitter between
#: radars): a plot at most this much older than the latest one seen is never dropped.
DEFAULT_REORDER_WINDOW_S = 2.0

Columns = Mapping[str, np.ndarray]


@dataclass
class Late:
    """Plots dropped for arriving too late: how many, the largest lateness (s), and the
    first one's lateness and 1-d column values (e.g. its file row, for the warning)."""

    n: int = 0
    max_late_s: float = 0.0
    first_late_s: float = 0.0
    first: dict[str, object] = field(default_factory=dict)

    def add(self, late_s: float, first: Callable[[], dict[str, object]]) -> None:
        if self.n == 0:
            self.first_late_s, self.first = late_s, first()
        self.n += 1
        self.max_late_s = max(self.max_late_s, late_s)

    def line(self, name: str, where: str, what: str = "plot") -> str:
        """The one warning line: ``NAME: 1 plot dropped, late by 40 s (...)``; ``where``
        names the first dropped row's place in the input, ``what`` the rows (``"plot"``,
        ``"sweep mark"``)."""
        plural = what if self.n == 1 else f"{what}s"
        by = (f"late by {self.max_late_s:.3g} s" if self.n == 1
              else f"late by up to {self.max_late_s:.3g} s")
        first = "" if self.n == 1 else f", the first late by {self.first_late_s:.3g} s"
        return (f"{name}: {self.n} {plural} dropped, {by} (after later plots had gone to "
                f"the tracker, beyond the reorder window; first at {where}{first})")


class ReorderBuffer:
    """Re-orders batches of plots (columns of equal length, one of them ``time``).

    :meth:`push` takes a batch in arrival order and returns the columns of the plots it
    releases, in time order, plus ``seq`` (each plot's 0-based arrival number);
    :meth:`flush` releases the rest at the end of the input. :attr:`late` records the
    plots dropped, :attr:`late_marks` the sweep marks (rows with ``mark`` true)."""

    def __init__(self, window_s: float = DEFAULT_REORDER_WINDOW_S) -> None:
        if not window_s >= 0:
            raise ValueError(f"reorder window must be >= 0 s, got {window_s!r}")
        self.window_s = float(window_s)
        self.latest = -np.inf
        self.released = -np.inf
        self.late = Late()
        self.late_marks = Late()  # rows with ``mark`` true: no plots
        self.n_in = 0
        self.reordered = 0
        self._heap: list[tuple[float, int]] = []  # (time, seq) of the held plots
        self._held: dict[str, np.ndarray] | None = None  # columns of held plots, by seq
        self._held_seq = np.zeros(0, np.int64)

    def push(self, cols: Columns) -> dict[str, np.ndarray]:
        """Add a batch (arrival order); the released plots' columns, time order."""
        t = np.asarray(cols["time"], float)
        seq0 = self.n_in
        self.n_in += t.size
        out: list[int] = []
        dropped: list[int] = []
        heap, window = self._heap, self.window_s
        latest, released = self.latest, self.released
        mark = cols.get("mark")
        for i, ti in enumerate(t.tolist()):
            if ti < released:
                late = self.late_marks if mark is not None and mark[i] else self.late
                late.add(latest - ti, lambda i=i: {  # type: ignore[misc]
                    k: _scalar(np.asarray(v)[i]) for k, v in cols.items()
                    if np.ndim(v) == 1})
                dropped.append(seq0 + i)
                continue
            if ti < latest:
                self.reordered += 1
            else:
                latest = ti
            heapq.heappush(heap, (ti, seq0 + i))
            edge = latest - window
            while heap and heap[0][0] < edge:
                released, s = heapq.heappop(heap)
                out.append(s)
        self.latest, self.released = latest, released
        return self._move(cols, seq0, out, dropped)

    def flush(self) -> dict[str, np.ndarray]:
        """Release every held plot (the input has ended)."""
        out = [s for _, s in sorted(self._heap)]
        self._heap = []
        if out:
            self.released = max(self.released, self._time_of(out[-1]))
        return self._move(None, self.n_in, out, [])

    def held(self) -> dict[str, np.ndarray] | None:
        """The columns of the plots held, in the order they would leave (time, then
        arrival); ``None`` when none."""
        if not self._heap or self._held is None:
            return None
        seq = np.array([s for _, s in sorted(self._heap)], np.int64)
        pos = np.searchsorted(self._held_seq, seq)
        return {k: v[pos] for k, v in self._held.items()}

    def _time_of(self, seq: int) -> float:
        assert self._held is not None
        return float(self._held["time"][np.searchsorted(self._held_seq, seq)])

    def _move(self, cols: Columns | None, seq0: int, out: list[int], dropped: list[int]
              ) -> dict[str, np.ndarray]:
        """Gather the released plots (by ``seq``) from the held ones and the batch; keep
        the rest held (those neither released nor ``dropped``: the heap's, in ``seq``
        order, found by a mask rather than a pass over the heap)."""
        if cols is not None and len(cols["time"]):
            new_seq = np.arange(seq0, seq0 + len(cols["time"]), dtype=np.int64)
            batch = {k: np.asarray(v) for k, v in cols.items()}
            if self._held is None:
                self._held, self._held_seq = batch, new_seq
            else:
                self._held = {k: np.concatenate((self._held[k], batch[k])) for k in batch}
                self._held_seq = np.concatenate((self._held_seq, new_seq))
        if self._held is None:
            return {}
        seq = np.asarray(out, np.int64)
        pos = np.searchsorted(self._held_seq, seq)
        result = {k: v[pos] for k, v in self._held.items()}
        result["seq"] = seq
        stay = np.ones(self._held_seq.size, bool)
        stay[pos] = False
        if dropped:
            stay[np.searchsorted(self._held_seq, np.asarray(dropped, np.int64))] = False
        self._held = {k: v[stay] for k, v in self._held.items()}
        self._held_seq = self._held_seq[stay]
        return result


def kept(time: np.ndarray, window_s: float = DEFAULT_REORDER_WINDOW_S) -> np.ndarray:
    """Which plots (times in arrival order) :class:`ReorderBuffer` lets through: the
    buffer's own rule replayed on the times alone, so that what is surveyed before
    tracking (the plots' area) is what the tracker will get."""
    return kept_and_late(time, window_s)[0]


def kept_and_late(time: np.ndarray, window_s: float = DEFAULT_REORDER_WINDOW_S
                  ) -> tuple[np.ndarray, Late]:
    """:func:`kept`, and the :class:`Late` record of the dropped plots (``first["row"]``:
    the 0-based arrival number of the first one)."""
    buf = ReorderBuffer(window_s)
    t = np.asarray(time, float)
    seq = [buf.push({"time": t, "row": np.arange(t.size)}).get("seq"),
           buf.flush().get("seq")]
    out = np.zeros(t.size, bool)
    for s in seq:
        if s is not None:
            out[s] = True
    return out, buf.late


def _scalar(v: object) -> object:
    """A NumPy scalar as its Python value (an object column's element as it is)."""
    return v.item() if isinstance(v, np.generic) else v
