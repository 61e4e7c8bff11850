"""Frames: how asynchronous plots are cut into the tracker's steps (``docs/mht.md``).

A rotating radar times each plot when its beam crossed it, and several radars interleave.
The tracker steps once per *frame*: the plots of **one sensor** over at most ``frame_s``
seconds (by default an eighth of that radar's rotation period — a 45° sector — or 1 s for a
sensor without a period). One sensor per frame keeps P1's rule of at most one plot per
target per step (a radar sees a target once per sweep); a short frame keeps each plot's
own time close to the frame's.

Frames are numbered in the order of their latest plot time (ties: sensor id, then first
row), which is the order the tracker processes them; within a frame rows keep time order.
Frames of different radars may overlap in time by less than one frame; the tracker
predicts every hypothesis to each plot's own time.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

#: Frame length (s) for a sensor without a rotation period.
DEFAULT_FRAME_S = 1.0
#: Fraction of a rotation period one frame spans (a 45° sector).
SECTOR_FRACTION = 1.0 / 8.0


def frame_lengths(periods: Mapping[int, float | None]) -> dict[int, float]:
    """``frame_s`` per sensor id: ``period · SECTOR_FRACTION``, or :data:`DEFAULT_FRAME_S`."""
    return {int(k): DEFAULT_FRAME_S if p is None else float(p) * SECTOR_FRACTION
            for k, p in periods.items()}


def make_frames(
    time: np.ndarray, sensor: np.ndarray, frame_s: Mapping[int, float] | float = DEFAULT_FRAME_S
) -> tuple[np.ndarray, np.ndarray]:
    """Cut time-stamped plots into frames.

    Parameters
    ----------
    time, sensor : (n,) each plot's time (s) and sensor id, in any order.
    frame_s : the longest frame per sensor id (s), or one length for all.

    Returns
    -------
    frame : (n,) frame index of each row (``0 … F−1``, in processing order).
    order : (n,) the row permutation that sorts the plots by frame, then time.

    A sensor's plots, in time order, start a new frame when the time since the frame's
    first plot would exceed its ``frame_s``.
    """
    time = np.asarray(time, dtype=float).reshape(-1)
    sensor = np.asarray(sensor, dtype=np.int64).reshape(-1)
    n = time.size
    if sensor.size != n:
        raise ValueError(f"{sensor.size} sensor ids for {n} plot times")
    if n == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    by_sensor = np.lexsort((np.arange(n), time, sensor))
    local = np.empty(n, np.int64)  # frame number within the sensor, per row of by_sensor
    for s in np.unique(sensor).tolist():
        length = frame_s if isinstance(frame_s, int | float) else frame_s.get(int(s))
        if length is None or not length > 0:
            raise ValueError(f"sensor {s}: frame length must be > 0, got {length!r}")
        pos = np.flatnonzero(sensor[by_sensor] == s)
        t = time[by_sensor[pos]]
        k, start, out = 0, t[0], np.empty(t.size, np.int64)
        for i, ti in enumerate(t.tolist()):  # greedy: a frame spans at most `length` seconds
            if ti - start > length:
                k, start = k + 1, ti
            out[i] = k
        local[pos] = out
    key_sensor = sensor[by_sensor]
    key = key_sensor * (n + 1) + local  # unique per (sensor, local frame)
    uniq, inv = np.unique(key, return_inverse=True)
    end = np.full(uniq.size, -np.inf)
    np.maximum.at(end, inv, time[by_sensor])
    first = np.full(uniq.size, n, np.int64)
    np.minimum.at(first, inv, by_sensor)
    usensor = uniq // (n + 1)
    rank = np.empty(uniq.size, np.int64)
    rank[np.lexsort((first, usensor, end))] = np.arange(uniq.size)
    frame = np.empty(n, np.int64)
    frame[by_sensor] = rank[inv]
    order = np.lexsort((np.arange(n), time, frame))
    return frame, order
