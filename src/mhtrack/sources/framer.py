"""Frames cut as the plots arrive: the same frames as :func:`mhtrack.frames.make_frames`,
each given out as soon as no later plot can change it.

Input: plots in time order (ties in input order), as batches of columns (``time``,
``sensor`` and any others). A sensor's frame starts at its first plot and takes the
sensor's plots while ``t − start ≤ frame_s`` — and, where the batches carry a ``sector``
column (the radar's own sectors, counted from its CAT034 sector crossings), while their
sector is the frame's first plot's; it is *closed* once a plot of that sensor
falls beyond (it starts the next frame), the stream's time ``T`` passes
``start + frame_s`` (every later plot has ``t ≥ T``), or — rows with ``mark`` true: the
radar's CAT034/CAT002 north marker or sector crossing, its ``sector`` the radar's count
of them with it, in time order among the plots — a mark of that sensor with a sector
after the frame's comes (the antenna has left the frame's sector: every plot of it is
in). A mark is no plot: it joins no frame. A radar that sends no marks, or whose mark
is lost, keeps the ``frame_s`` rule. :func:`~mhtrack.frames.make_frames`
numbers frames by (latest plot time ``end``, sensor id); a closed frame ``F`` therefore
goes out once

* ``end_F < T`` (a frame not yet started ends at ``≥ T``), and
* every open frame ``G`` has ``(end_G, sensor_G) > (end_F, sensor_F)`` (an open frame's
  end only grows),

and closed frames go out in ``(end, sensor)`` order. Frames of one sensor have distinct
ends, so make_frames' last tie-break (first row) never decides. Within a frame plots keep
their input order, which is time order.

**Release by radar** (``release="radar"``, an option of ``live``, off by default): a
closed frame goes out once ``end_F < T`` alone — its own plots are all in — without
waiting for the open frames of other radars that might still end before it (the wait of
the global order is up to one frame length of the slowest radar). Frames then go out in
the order they are complete, not make_frames' order; a frame that closes with its end
before that of a frame already given out gets the latter's time as its reference time
(its plots keep their own times), so that frame times never go back. The tracker then
sees another order of the same frames than ``track`` on the file: its output differs
(``docs/live.md``, *Latency*).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field

import numpy as np

from mhtrack.frames import DEFAULT_FRAME_S
from mhtrack.names import RELEASES


@dataclass
class _Open:
    """A sensor's frame being filled: its start, end, sector and the plots' positions."""

    start: float
    end: float
    sector: int = 0
    parts: list[tuple[int, np.ndarray]] = field(default_factory=list)  # (batch id, rows)
    mark: dict[str, np.ndarray] | None = None  # the mark that closed it (its row, copied)
    mark_at: tuple[int, int] = (-1, -1)  # the mark's batch id and row in it


@dataclass(frozen=True)
class Frame:
    """A finished frame: its number, sensor, reference time (its latest plot's), the
    columns of its plots in time order and ``mark``, the values of the row of the sweep
    mark that closed it (``None``: closed by a plot, the stream's time or the end)."""

    index: int
    sensor: int
    time: float
    cols: dict[str, np.ndarray]
    mark: dict[str, object] | None = None


class Framer:
    """Cuts time-ordered batches of plots into one-sensor frames (module docstring).

    ``frame_s`` gives the longest frame per sensor id (s) or one length for all; a sensor
    missing from the mapping gets :data:`~mhtrack.frames.DEFAULT_FRAME_S`; ``release``
    ``"time"`` (make_frames' order) or ``"radar"`` (module docstring)."""

    def __init__(self, frame_s: Mapping[int, float] | float = DEFAULT_FRAME_S, *,
                 release: str = "time") -> None:
        if release not in RELEASES:
            raise ValueError(f"unknown release {release!r} (expected "
                             f"{', '.join(RELEASES)})")
        self.release = release
        self.last_time = -np.inf  # the reference time of the last frame given out
        self.frame_s = frame_s
        self.now = -np.inf
        self.n_frames = 0
        self._open: dict[int, _Open] = {}
        self._closed: list[tuple[float, int, _Open]] = []
        self._batches: dict[int, dict[str, np.ndarray]] = {}
        self._uses: dict[int, int] = {}
        self._next_batch = 0

    @property
    def batches_held(self) -> int:
        """The batches kept for the plots of frames not yet given out (memory): each is
        freed once its last such frame is out, a batch without plots at once."""
        return len(self._batches)

    def _length(self, sensor: int) -> float:
        f = self.frame_s
        length = f if isinstance(f, int | float) else f.get(sensor, DEFAULT_FRAME_S)
        if not length > 0:
            raise ValueError(f"sensor {sensor}: frame length must be > 0, got {length!r}")
        return float(length)

    def push(self, cols: Mapping[str, np.ndarray]) -> Iterator[Frame]:
        """Add a batch (time order, after every earlier batch); the frames it completes."""
        t = np.asarray(cols["time"], float)
        if t.size == 0:
            return
        if t[0] < self.now or (t.size > 1 and np.any(np.diff(t) < 0)):
            raise ValueError("plots must reach the framer in time order")
        b = self._next_batch
        self._next_batch += 1
        self._batches[b] = {k: np.asarray(v) for k, v in cols.items()}
        sensor = np.asarray(cols["sensor"], np.int64)
        sector = np.asarray(cols["sector"], np.int64) if "sector" in cols else None
        mark = np.asarray(cols["mark"], bool) if "mark" in cols else None
        uses = 0
        for s in np.unique(sensor).tolist():
            rows = np.flatnonzero(sensor == s)
            if mark is not None and mark[rows].any():  # plots between marks, in turn
                uses += self._with_marks(b, s, rows, t, sector, mark)
                continue
            uses += self._plots(b, s, rows, t, sector)
        if uses:
            self._uses[b] = uses
        else:  # no plot of it in a frame (marks only): each closing mark is copied
            del self._batches[b]
        self.now = float(t[-1])
        yield from self._ready(final=False)

    def _with_marks(self, b: int, s: int, rows: np.ndarray, t: np.ndarray,
                    sector: np.ndarray | None, mark: np.ndarray) -> int:
        """Sensor ``s``'s rows of batch ``b`` with marks among them: the plots before
        each mark, then the mark closes the open frame if its sector is later."""
        assert sector is not None
        uses = 0
        at = rows[mark[rows]]
        cut = 0
        for m in at.tolist():
            upto = int(np.searchsorted(rows, m))
            if upto > cut:
                uses += self._plots(b, s, rows[cut:upto], t, sector)
            fr = self._open.get(s)
            if fr is not None and fr.sector < int(sector[m]):
                fr.mark = {k: v[m:m + 1].copy() for k, v in self._batches[b].items()}
                fr.mark_at = (b, m)
                self._close(s)
            cut = upto + 1
        if cut < rows.size:
            uses += self._plots(b, s, rows[cut:], t, sector)
        return uses

    def _plots(self, b: int, s: int, rows: np.ndarray, t: np.ndarray,
               sector: np.ndarray | None) -> int:
        """Sensor ``s``'s plots ``rows`` of batch ``b`` into its frames; the number of
        frame parts made."""
        uses = 0
        ts = t[rows]
        sec = sector[rows] if sector is not None else None
        fr = self._open.get(s)
        length = self._length(s)
        cut = 0
        while cut < rows.size:
            if fr is None:
                fr = self._open[s] = _Open(float(ts[cut]), float(ts[cut]),
                                           0 if sec is None else int(sec[cut]))
            # plots of this frame: t − start ≤ length, computed as make_frames does
            # (the difference of sorted times is sorted)
            stop = cut + int(np.searchsorted(ts[cut:] - fr.start, length, side="right"))
            if sec is not None:  # and of the frame's sector
                other = np.flatnonzero(sec[cut:stop] != fr.sector)
                stop = cut + int(other[0]) if other.size else stop
            if stop > cut:
                fr.parts.append((b, rows[cut:stop]))
                fr.end = float(ts[stop - 1])
                uses += 1
            if stop < rows.size:  # a later plot starts the next frame
                self._close(s)
                fr = None
            cut = stop
        return uses

    def flush(self) -> Iterator[Frame]:
        """Every remaining frame (the input has ended)."""
        for s in list(self._open):
            self._close(s)
        yield from self._ready(final=True)

    def pending(self) -> dict[str, np.ndarray] | None:
        """The columns of every row held — the plots of open frames and of closed frames
        not yet given out, and the mark that closed each of the latter —, in the order
        pushed (time order); ``None`` when none. Pushed into a fresh framer (same
        lengths) they give the same frames as here, each out at the same push."""
        at_b: list[np.ndarray] = []
        at_row: list[np.ndarray] = []
        cols: list[Mapping[str, np.ndarray]] = []
        for fr in (*self._open.values(), *(c[2] for c in self._closed)):
            for b, rows in fr.parts:
                at_b.append(np.full(rows.size, b))
                at_row.append(rows)
                cols.append({k: v[rows] for k, v in self._batches[b].items()})
            if fr.mark is not None:
                at_b.append(np.array([fr.mark_at[0]]))
                at_row.append(np.array([fr.mark_at[1]]))
                cols.append(fr.mark)
        if not cols:
            return None
        order = np.lexsort((np.concatenate(at_row), np.concatenate(at_b)))
        return {k: np.concatenate([c[k] for c in cols])[order] for k in cols[0]}

    def _close(self, sensor: int) -> None:
        fr = self._open.pop(sensor)
        self._closed.append((fr.end, sensor, fr))

    def _ready(self, final: bool) -> Iterator[Frame]:
        for s, fr in list(self._open.items()):  # closed by the stream's time
            if self.now - fr.start > self._length(s):
                self._close(s)
        self._closed.sort(key=lambda c: (c[0], c[1]))
        while self._closed:
            end, s, fr = self._closed[0]
            if not final:
                if not end < self.now:
                    break
                if self.release == "time" and any(
                        (g.end, gs) < (end, s) for gs, g in self._open.items()):
                    break
            self._closed.pop(0)
            yield self._emit(s, fr)

    def _emit(self, sensor: int, fr: _Open) -> Frame:
        pieces: dict[str, list[np.ndarray]] = {}
        for b, rows in fr.parts:
            for k, v in self._batches[b].items():
                pieces.setdefault(k, []).append(v[rows])
            self._uses[b] -= 1
            if self._uses[b] == 0:
                del self._batches[b], self._uses[b]
        cols = {k: v[0] if len(v) == 1 else np.concatenate(v) for k, v in pieces.items()}
        if self.release == "radar":  # frame times never go back
            self.last_time = max(self.last_time, fr.end)
        mark = None if fr.mark is None else {k: v[0] for k, v in fr.mark.items()}
        out = Frame(self.n_frames, sensor, fr.end if self.release == "time"
                    else self.last_time, cols, mark)
        self.n_frames += 1
        return out
