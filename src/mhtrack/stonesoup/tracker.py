"""mhtrack's MHT as a Stone Soup ``Tracker``.

:class:`MHTrackTracker` reads any Stone Soup detector — an iterable of
``(time, set[Detection])`` — and yields ``(time, set[Track])`` like Stone Soup's own
trackers, so that its ``MetricManager`` (OSPA, GOSPA, SIAP) and plotters work on the
output unchanged. Inside, each step becomes one mhtrack :class:`~mhtrack.records.Scan`
(positions and ``R`` by :func:`~mhtrack.stonesoup.convert.detections_to_xy`) for the
MHT that :func:`mhtrack.build.make_tracker` builds.
"""

from __future__ import annotations

import bisect
import datetime
from collections import deque
from collections.abc import Iterator
from typing import Any

import numpy as np
from stonesoup.base import Property
from stonesoup.tracker.base import Tracker
from stonesoup.types.hypothesis import SingleHypothesis
from stonesoup.types.prediction import GaussianStatePrediction
from stonesoup.types.track import Track
from stonesoup.types.update import GaussianStateUpdate

from mhtrack.build import make_tracker
from mhtrack.mht import MHTConfig, MHTTracker
from mhtrack.records import Scan, TrackTable
from mhtrack.stonesoup.convert import (
    POSITION_MAPPING,
    detections_to_xy,
    seconds,
    split_by_time,
)


class MHTrackTracker(Tracker):
    """mhtrack's track-oriented MHT behind Stone Soup's ``Tracker`` interface.

    Each detector step ``(time, detections)`` is one scan of the MHT per distinct
    detection timestamp (:func:`~mhtrack.stonesoup.convert.split_by_time`; one scan when
    every detection has the step's time), in time order: several sensors' detections with
    their own timestamps are scans of their own. Each scan is taken as **one look** at
    every target (at most one plot per target, ``P_D`` of the config): detections of two
    sensors with one timestamp should be fused first.

    Output: the confirmed tracks of the best global hypothesis at this step (``tracks``),
    each a persistent Stone Soup ``Track`` (one per mhtrack track id, ``id``
    ``"mhtrack-<id>"``) whose states are ``GaussianStateUpdate`` (the state used a
    detection; its hypothesis holds that detection) or ``GaussianStatePrediction`` (a
    miss), mean ``(x, vx, y, vy)`` and covariance in that order. A track confirmed at this
    step also gets its tentative past (the MHT's ``last_backfill``), as Stone Soup's
    multi-measurement initiator gives a new track its first states.
    """

    detector: Any = Property(default=None, doc="Stone Soup detector: iterable of "
                             "(time, set of Detection)")
    tracker: str = Property(default="mht-agmm", doc="mhtrack tracker name "
                            "(mhtrack.names.TRACKERS): mht, mht-gmm, mht-agmm, mht-map, "
                            "mht-fgmm, mht-mapgmm")
    config: Any = Property(default=None, doc="mhtrack.mht.MHTConfig (default: MHTConfig())")
    clutter_density: float = Property(default=None, doc="known clutter density per m² per "
                                      "scan of tracker 'mht'")
    mht: Any = Property(default=None, doc="a ready mhtrack.mht.MHTTracker (then tracker, "
                        "config and clutter_density are not used)")
    measurement_model: Any = Property(default=None, doc="model of detections that carry none")
    position_mapping: tuple = Property(default=POSITION_MAPPING, doc="indices of x and y in "
                                       "the targets' state vector")

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.engine: MHTTracker = self.mht if self.mht is not None else make_tracker(
            self.tracker, self.config if self.config is not None else MHTConfig(),
            clutter_density=self.clutter_density)
        self.epoch: datetime.datetime | None = None
        self._detector_iter: Iterator[Any] | None = None
        self._by_id: dict[int, Track] = {}
        self._live: set[Track] = set()
        self._k = 0
        self._row = 0
        # detections of the last steps by row id, for the states of the tentative past
        self._dets: dict[int, Any] = {}
        self._steps: deque[tuple[int, int]] = deque()
        self._stamps: dict[float, datetime.datetime] = {}  # scan times (s) → datetime
        self._parts: list[TrackTable] = []

    @property
    def tracks(self) -> set[Track]:
        """The tracks reported at the last step."""
        return set(self._live)

    @property
    def all_tracks(self) -> set[Track]:
        """Every track reported so far."""
        return set(self._by_id.values())

    @property
    def table(self) -> TrackTable:
        """Everything reported so far as an mhtrack :class:`TrackTable` (times in seconds
        after :attr:`epoch`; tentative rows flagged), for mhtrack's metrics."""
        return TrackTable.concat(self._parts).sorted()

    def __iter__(self) -> Iterator[tuple[datetime.datetime, set[Track]]]:
        if self.detector is None:
            raise AttributeError("MHTrackTracker has no detector to iterate over")
        self._detector_iter = iter(self.detector)
        return self

    def __next__(self) -> tuple[datetime.datetime, set[Track]]:
        if self._detector_iter is None:
            iter(self)
        time, detections = next(self._detector_iter)  # type: ignore[arg-type]
        return self.update_tracker(time, detections)

    def update_tracker(self, time: datetime.datetime, detections: Any
                       ) -> tuple[datetime.datetime, set[Track]]:
        """One step: ``detections`` at ``time`` through the MHT; the tracks after it."""
        if self.epoch is None:
            self.epoch = time
        for t, dets in split_by_time(time, detections):
            out = self.engine.step(self._scan(t, dets))
            backfill = self.engine.last_backfill
            self._parts += [out, backfill]
            self._stamps[seconds(t, self.epoch)] = t
            for r in range(len(backfill)):
                self._record(backfill, r)
            self._live = {self._record(out, r) for r in range(len(out))}
        return time, self.tracks

    def _scan(self, time: datetime.datetime, dets: list[Any]) -> Scan:
        z, R = detections_to_xy(dets, position_mapping=self.position_mapping,
                                measurement_model=self.measurement_model)
        n = len(dets)
        assert self.epoch is not None
        rows = np.arange(self._row, self._row + n, dtype=np.int64)
        self._dets.update(zip(rows.tolist(), dets, strict=True))
        self._steps.append((self._row, n))
        while len(self._steps) > self.engine.config.history_scans + 2:
            first, m = self._steps.popleft()
            for i in range(first, first + m):
                self._dets.pop(i, None)
        self._row += n
        self._k += 1
        return Scan(self._k - 1, seconds(time, self.epoch), z, np.zeros(n, np.int64), rows, R)

    def _record(self, table: TrackTable, r: int) -> Track:
        """Row ``r`` of ``table`` as a state of its persistent Track (created when new)."""
        assert self.epoch is not None and table.P is not None
        tsec = float(table.time[r])
        ts = self._stamps.get(tsec) or self.epoch + datetime.timedelta(seconds=tsec)
        mean = np.array([[table.x[r]], [table.vx[r]], [table.y[r]], [table.vy[r]]])
        det = self._dets.get(int(table.plot[r]))
        if det is not None:
            state = GaussianStateUpdate(mean, table.P[r], SingleHypothesis(None, det),
                                        timestamp=ts)
        else:
            state = GaussianStatePrediction(mean, table.P[r], timestamp=ts)
        tid = int(table.track_id[r])
        trk = self._by_id.get(tid)
        if trk is None:
            trk = self._by_id[tid] = Track([state], id=f"mhtrack-{tid}")
        elif not len(trk.states) or trk.states[-1].timestamp <= ts:
            trk.append(state)
        else:  # a tentative-past state before states the track already has
            times = [s.timestamp for s in trk.states]
            trk.insert(bisect.bisect_right(times, ts), state)
        return trk
