"""Checkpoints of a live run (``docs/live.md``, *Checkpoints and restart*): the tracker's
full state (:meth:`~mhtrack.mht.MHTTracker.save`, one ``.npz`` written atomically) with
what the live run needs to continue — the next frame's number, the time axis (``day0``,
``latest``: the day of later times of day), the latest time tracked, the next tick of
the period output, the next plot's row number (the tracker's plot windows name plots
by row: numbers must not repeat), the duplicate filter's last data blocks (their
digests: a redundant-LAN copy late across the restart is still a copy), the plots
received but not yet tracked (in the re-order window and in frames not yet tracked,
with the sweep marks among them and each radar's count of marks: ``--sector-frames``
numbers sectors on after the restart) and, with
bias estimation, its state (:mod:`~mhtrack.pipeline.registration_state`) and the
tracking options the run was started with, ``--sector-frames`` among them
(:func:`options_record`) — under ``meta["extra"]``. A run resumed from it
therefore makes the same frames as a run never stopped, given the same datagrams after
the checkpoint; a run resumed with other tracking options is refused
(:func:`check_options`: the saved tracker would silently keep the old ones; the plots
held were cut with or without their sectors), and so is a checkpoint of plots held with
their sectors but without the counts of crossings (:func:`decode_pending`: written
before they were kept).

:class:`CheckpointSink` writes one every ``every_s`` seconds **of data time** (the frames'
times: the same input checkpoints at the same frames) and a final one when the run ends
(input ended, or stopped by SIGTERM/Ctrl-C after the held frames were tracked).
:func:`read_checkpoint` gives the tracker back (:func:`~mhtrack.build.load_tracker`:
the same track ids continue) and the bookkeeping.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from mhtrack.errors import InputError
from mhtrack.sinks.base import FrameOutput, Sink

if TYPE_CHECKING:
    from mhtrack.mht import MHTTracker
    from mhtrack.pipeline.options import TrackOptions

#: Version of the ``extra`` bookkeeping.
LIVE_FORMAT = 1


@dataclass(frozen=True)
class LiveState:
    """What a live run continues from besides the tracker."""

    #: The number of the next frame.
    next_frame: int
    #: The time axis: capture day of its day 0 (``None``: no capture times) and the
    #: latest time on it (``None``: nothing received).
    axis_day0: float | None
    axis_latest: float | None
    #: The latest frame time tracked (later plots only; earlier ones are late drops).
    last_time: float | None
    #: The next tick of the period output (``None``: none yet or no period output).
    next_tick: int | None
    #: The plots received but not yet in a frame tracked (:func:`encode_pending`).
    pending: dict[str, Any] | None = None
    #: The running row number of the next plot (the tracker knows plots by row).
    next_row: int = 0
    #: The duplicate filter's last blocks (``DuplicateFilter.recent``: hex digests,
    #: oldest first; ``None``: none): a redundant-LAN copy arriving after the restart
    #: of a block received before it is still a copy.
    duplicates: str | None = None
    #: The bias estimation's state (``--estimate-bias``;
    #: :func:`~mhtrack.pipeline.registration_state.encode_state`), else ``None``.
    bias: dict[str, Any] | None = None
    format: int = LIVE_FORMAT
    #: The tracking options of the run (:func:`options_record`; ``None``: a checkpoint
    #: written before they were kept, not checked).
    options: dict[str, Any] | None = None


#: :class:`~mhtrack.pipeline.TrackOptions` fields not compared on resume: the bias prior
#: (a resumed run continues from the checkpoint's bias state, not from a prior).
UNCHECKED_OPTIONS = ("bias_prior",)


def options_record(options: TrackOptions, sectors: bool = False) -> dict[str, Any]:
    """``options`` as JSON (every field but :data:`UNCHECKED_OPTIONS`) and
    ``sector_frames`` (``live --sector-frames``: ``sectors``), as saved in a checkpoint
    and compared by :func:`check_options`."""
    import json

    fields = {k: v for k, v in asdict(options).items() if k not in UNCHECKED_OPTIONS}
    fields["sector_frames"] = bool(sectors)
    return dict(json.loads(json.dumps(fields, sort_keys=True, default=str)))


def saved_sectors(state: LiveState) -> bool | None:
    """Whether the run that wrote ``state`` cut frames at its radars' sectors: its
    options' ``sector_frames``, else (written before it was kept) whether the plots held
    carry their ``sector`` column; ``None`` when neither tells (nothing held)."""
    if state.options is not None and "sector_frames" in state.options:
        return bool(state.options["sector_frames"])
    pending = state.pending or {}
    held = [c for c in (pending.get("framed"), pending.get("held")) if isinstance(c, dict)]
    return None if not held else any("sector" in c for c in held)


def check_options(path: str | Path, state: LiveState, options: TrackOptions,
                  sectors: bool = False) -> None:
    """An :class:`InputError` in one line naming the checkpoint and each field that
    differs when ``options`` and ``sectors`` (``--sector-frames``) are not those
    ``state`` was saved with; a checkpoint without options is checked for
    ``sector_frames`` alone, and that where known (:func:`saved_sectors`)."""
    now = options_record(options, sectors)
    was = {} if state.options is None else dict(state.options)
    keys = set(now) | set(was) if state.options is not None else set()
    was.pop("sector_frames", None)
    keys.discard("sector_frames")
    if (cut := saved_sectors(state)) is not None:
        was["sector_frames"] = cut
        keys.add("sector_frames")
    diff = [f"{k} {was.get(k)!r} there, {now.get(k)!r} here"
            for k in sorted(keys) if was.get(k) != now.get(k)]
    if diff:
        raise InputError(f"{path}: written with other tracking options ({'; '.join(diff)})"
                         ": resume with the same options, or start afresh without "
                         "--resume", file=str(path))


def encode_pending(pending: dict[str, Any] | None) -> dict[str, Any] | None:
    """:meth:`~mhtrack.sources.datagrams.DatagramSource.pending` as JSON: each column a
    list (floats to the bit: JSON keeps Python's shortest round-trip form), the times
    ``None`` when infinite, ``marks`` each radar's count of sweep marks; ``None`` when no
    row (plot or crossing) is held — the counts are then not needed: the framer only
    compares a frame's sector with its own radar's later crossings, so with no frame
    held a resumed run numbering sectors from 0 again cuts the same frames."""
    if pending is None or (pending["framed"] is None and pending["held"] is None):
        return None
    out: dict[str, Any] = {k: None if pending[k] is None or not math.isfinite(pending[k])
                           else float(pending[k]) for k in ("latest", "released")}
    for part in ("framed", "held"):
        cols = pending[part]
        out[part] = None if cols is None else {k: _column(v) for k, v in cols.items()}
    out["marks"] = {str(k): int(v) for k, v in sorted(pending.get("marks", {}).items())}
    return out


def _marks(saved: Any) -> dict[int, int]:
    """Each radar's count of sweep marks, by radar id, from ``{"id": count}``; a
    ``ValueError`` naming an entry that is no integer id with an integer count ≥ 0."""
    if not isinstance(saved, dict):
        raise ValueError(f"marks {saved!r} are not an object")
    for k, v in saved.items():
        if not (k.lstrip("-").isdigit() and type(v) is int and v >= 0):
            raise ValueError(f"marks: {k!r}: {v!r} is no radar id with a count >= 0")
    return {int(k): v for k, v in saved.items()}


def _array(saved: dict[str, Any]) -> np.ndarray:
    """A held column read back with its dtype: numbers, booleans or text only (text
    columns of plot attributes, such as the callsign, are object arrays of str)."""
    dtype = np.dtype(saved["dtype"])
    values = saved["values"]
    if dtype.kind == "O" and all(isinstance(v, str) for v in values):
        out = np.empty(len(values), object)
        out[:] = values
        return out
    if dtype.kind not in "biufU":
        raise ValueError(f"a held column of dtype {saved['dtype']!r} (numbers or text only)")
    return np.asarray(values, dtype)


def _column(values: Any) -> dict[str, Any]:
    """One held column as JSON: its NumPy dtype (text columns of plot attributes are
    kept as text, numbers to the bit) and its values."""
    a = np.asarray(values)
    return {"dtype": a.dtype.str, "values": a.tolist()}


def decode_pending(saved: dict[str, Any] | None) -> dict[str, Any] | None:
    """The plots held, back as columns for ``DatagramSource(pending=...)``; their
    ``file_row`` is ``-1`` (numbers of the earlier run, not of this one's input), and so
    is a sweep mark's ``offset`` (no datagram of this run: ``docs/live.md``, *Health and
    latency*); ``marks``, each radar's count of sweep marks, by radar id. A checkpoint
    written before the counts were kept has none: refused (``ValueError``) if it holds
    plots with their sectors (``--sector-frames``: they would be numbered from 0 again,
    other frames), else read with none."""
    if saved is None:
        return None
    out: dict[str, Any] = {k: -math.inf if saved[k] is None else float(saved[k])
                           for k in ("latest", "released")}
    if "marks" not in saved and any(isinstance(saved[p], dict) and "sector" in saved[p]
                                    for p in ("framed", "held")):
        raise ValueError("pending: plots held with their sectors but no 'marks' (each "
                         "radar's count of sector crossings): written before sector "
                         "counts were kept: start afresh without --resume")
    out["marks"] = _marks(saved.get("marks", {}))
    for part in ("framed", "held"):
        cols = saved[part]
        if cols is None:
            out[part] = None
            continue
        arrays = {k: _array(v) for k, v in cols.items()}
        if "R" in arrays:
            arrays["R"] = arrays["R"].reshape(-1, 2, 2)
        arrays["file_row"] = np.full(len(arrays["time"]), -1, np.int64)
        if "mark" in arrays and "offset" in arrays:  # bytes of the earlier run's input
            arrays["offset"] = np.where(arrays["mark"], -1, arrays["offset"])
        out[part] = arrays
    return out


class CheckpointSink(Sink):
    """The tracker (``tracker()``, the one being stepped) and ``state()`` saved to
    ``path`` every ``every_s`` s of data time (``None``: only at the end) and when the
    run ends, with the run's tracking ``options`` and ``sectors`` (``--sector-frames``;
    :func:`options_record`; ``options`` ``None``: the state's own). :attr:`written`
    counts the checkpoints."""

    def __init__(self, path: str | Path, tracker: Callable[[], MHTTracker],
                 state: Callable[[], LiveState], every_s: float | None = None,
                 options: TrackOptions | None = None, sectors: bool = False) -> None:
        if every_s is not None and not every_s > 0:
            raise ValueError(f"checkpoint period must be > 0 s, got {every_s!r}")
        self.path, self.tracker, self.state = Path(path), tracker, state
        self.options = None if options is None else options_record(options, sectors)
        self.every_s = math.inf if every_s is None else float(every_s)
        self.written = 0
        self._last: float | None = None

    def save(self) -> None:
        """Write a checkpoint now."""
        state = self.state()
        if self.options is not None:
            state = replace(state, options=self.options)
        self.tracker().save(self.path, extra=asdict(state))
        self.written += 1

    def write(self, out: FrameOutput) -> None:
        t = float(out.frame.time)
        if self._last is None:
            self._last = t
        elif t - self._last >= self.every_s:
            self.save()
            self._last = t

    def close(self) -> None:
        self.save()


def read_checkpoint(path: str | Path, options: TrackOptions | None = None,
                    sectors: bool = False) -> tuple[MHTTracker, LiveState]:
    """The tracker and the live bookkeeping of a checkpoint written by
    :class:`CheckpointSink`; an :class:`InputError` naming the file otherwise, or when
    ``options`` and ``sectors`` are not those it was written with
    (:func:`check_options`; not checked without ``options``)."""
    from mhtrack.build import load_tracker
    from mhtrack.io.asterix.duplicates import stream_filter
    from mhtrack.mht.state import saved_meta

    meta: dict[str, Any] = saved_meta(path)
    extra = meta.get("extra")
    if not isinstance(extra, dict) or extra.get("format") != LIVE_FORMAT:
        raise InputError(f"{path}: member 'meta': no live checkpoint (field 'extra' of "
                         f"format {LIVE_FORMAT}): not written by mhtrack live", file=str(path))
    try:
        state = LiveState(**extra)
        if state.options is not None and not isinstance(state.options, dict):
            raise ValueError(f"options {state.options!r} are not an object")
        decode_pending(state.pending)  # the plots held must read back
        if state.duplicates is not None:  # and the duplicate filter's blocks
            stream_filter().restore(state.duplicates)
    except (TypeError, ValueError, KeyError, AttributeError) as e:
        raise InputError(f"{path}: member 'meta': field 'extra': {e}", file=str(path)) from None
    if options is not None:
        check_options(path, state, options, sectors)
    return load_tracker(path), state
