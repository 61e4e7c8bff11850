"""The first rotations of a live feed, surveyed as ``track`` surveys a recording
(``docs/live.md``, *Without a density or periods*): when the new-target density is not
given, or a radar's rotation period is not in the sensors file, ``live`` holds the
datagrams of the first rotations, then

* each radar's **period** comes from its CAT034/CAT002 sweep marks so far
  (:func:`~mhtrack.io.asterix.decode.sweep_periods`: the median I034/041, else the
  median interval between north markers — at least two of them);
* the **new-target density** (and the known κ of ``--tracker mht``) from the held
  plots by the same rule as ``track`` applies to a whole recording
  (:func:`~mhtrack.pipeline.options.choose`: for rotating radars,
  :func:`~mhtrack.build.radar_rule` — their reach, periods and plots per rotation).

The warm-up ends once the stream's time covers :data:`WARMUP_ROTATIONS` rotations of
the slowest radar seen and every radar seen has a period, or after :data:`MAX_WARMUP_S`
seconds of stream time (radars still without a period are then refused, by name), or at
a stop. The datagrams held are then tracked first, in order: nothing is lost, the first
frames only leave later (their latency includes the warm-up).
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from mhtrack.io.asterix.decode import MARKS, Decoder, sweep_periods
from mhtrack.io.asterix.duplicates import stream_filter
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.timeaxis import TimeAxis
from mhtrack.models.radars import SensorSet
from mhtrack.sources.base import Survey

#: Rotations of the slowest radar the warm-up covers.
WARMUP_ROTATIONS = 2.0
#: Longest warm-up (s of stream time).
MAX_WARMUP_S = 120.0


@dataclass(frozen=True)
class Warmup:
    """What the first rotations gave: the datagrams held (``(bytes, receive time)``, to
    be tracked first), each radar's period, the survey of their plots, the stream time
    they span (s)."""

    datagrams: list[tuple[bytes, float]]
    periods: dict[int, float]
    survey: Survey | None
    span_s: float


def warm_up(datagrams: Iterator[tuple[bytes, float]], sensors: SensorSet, *, name: str,
            use_receive_time: bool, reorder_window_s: float | None,
            stop: threading.Event, rotations: float = WARMUP_ROTATIONS,
            max_s: float = MAX_WARMUP_S) -> Warmup:
    """Hold ``datagrams`` until the warm-up ends (module docstring); the survey of what
    was held. ``use_receive_time``: the receive times give the day (``day_from``)."""
    from mhtrack.sources.base import IDLE
    from mhtrack.sources.datagrams import DatagramSource

    given = {s.id: float(s.period) for s in sensors.sensors if s.period is not None}
    ids = {s.id for s in sensors.sensors if s.kind == "polar"}  # radars waited for
    decoder = Decoder(duplicates=stream_filter())
    problems, axis = Problems(), TimeAxis()
    held: list[tuple[bytes, float]] = []
    marks: list[tuple[Any, ...]] = []
    seen: set[int] = set()
    periods = dict(given)
    first = last = None
    offset = 0
    for item in datagrams:
        if item is IDLE:  # a quiet feed: nothing is framed yet
            continue
        data, when = item
        held.append((data, when))
        new_marks = False
        for _, what, found in decoder.blocks(data, offset, problems,
                                             when if use_receive_time else None):
            t = axis.times_list([r[0] for r in found], when if use_receive_time else None)
            seen.update(int(r[1]) for r in found if int(r[1]) in ids)
            if what == MARKS:
                marks.extend((ti, *r[1:5]) for ti, r in zip(t, found, strict=True))
                new_marks = True
            if t:
                first = min(t) if first is None else min(first, *t)
                last = max(t) if last is None else max(last, *t)
        offset += len(data)
        if new_marks:
            periods = {**_periods(marks), **given}
        span = 0.0 if first is None or last is None else last - first
        if stop.is_set() or span >= max_s:
            break
        if seen and seen <= set(periods) and span >= rotations * max(
                periods[s] for s in seen):
            break
    survey = None
    if held:
        source = DatagramSource(held if use_receive_time else [d for d, _ in held],
                                sensors=sensors, name=name,
                                reorder_window_s=reorder_window_s)
        found, survey = source.periods_and_survey()
        periods = {**found, **given}
    return Warmup(held, periods, survey, 0.0 if first is None or last is None
                  else last - first)


def _periods(marks: list[tuple[Any, ...]]) -> dict[int, float]:
    cols = list(zip(*marks, strict=True))
    return sweep_periods({k: np.array(c, dtype=d) for k, c, d in zip(
        ("time", "sensor", "kind", "azimuth", "period"), cols,
        (float, np.int64, np.int64, float, float), strict=True)})
