"""A surveillance picture split over machines by region, with system track ids kept
across the borders (``docs/scaling.md``).

**Regions.** A :class:`Partition` is a set of *cores* — boxes that do not overlap, one per
region — and an ``overlap_m``: region ``i`` is given every plot within its core widened by
``overlap_m`` on each side (:meth:`Partition.split`), so near a border both neighbours see
the same aircraft. Each region runs its own tracker on its plots, frame by frame
(:class:`RegionTracker`: the object one machine holds; its frames keep the input's plot
rows, so its tracks name the input's plots). A region's tracks carry its own track ids.

**System ids and hand-over** (:class:`HandOver`, the coordinator every region reports to;
ours, after the multi-unit coordination of en-route tracking systems). Each system track
has one *owner* region, and only the owner publishes it: a picture with each aircraft
once. For each region's report row, in time order:

1. a region track already *linked* to a system id keeps it;
2. otherwise it is matched to a system track **owned by another region**, last reported
   within ``max_age_s``, that no track of this region is linked to: the nearest whose
   position, moved at constant velocity to the row's time, is within ``gate_m`` and whose
   velocity differs by at most ``gate_v`` (both aircraft tracks of the overlap, seen by
   both regions: the hand-over message is the owner's state and id). The row's track is
   then linked to that id;
3. otherwise, if the row lies in the region's core, a new system id, owned by it; else
   (in the overlap, not matched yet) it waits, unpublished.

Ownership moves when a linked track of another region reports from **its own core** (the
aircraft crossed the border and the neighbour has it), or when the owner has not reported
the id for ``max_age_s`` (its track ended) and a linked track reports; the new owner
publishes from its next report if the former one already did at that frame. An aircraft
that flies from one core into the next keeps its system id, provided its new region
confirmed a track on it while it was in the overlap: the overlap must be wider than the
distance flown while a track is confirmed, plus the gate.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from mhtrack.mht import MHTConfig
from mhtrack.models.clutter import Region
from mhtrack.models.radars import SensorSet
from mhtrack.records import Scan, TrackTable

#: Defaults of :class:`HandOver` (ours): en-route separation is 5 NM (9.3 km), so a 2 km
#: gate holds one aircraft; 60 m/s covers a turn's velocity change over a few looks.
GATE_M = 2_000.0
GATE_V = 60.0
MAX_AGE_S = 30.0


@dataclass(frozen=True)
class Partition:
    """Region cores (boxes, m, in the plots' local frame; they must not overlap) and the
    overlap (m) each region's plots reach beyond its core."""

    cores: tuple[Region, ...]
    overlap_m: float

    def __post_init__(self) -> None:
        if not self.cores:
            raise ValueError("Partition: at least one region core is needed")
        if not self.overlap_m >= 0:
            raise ValueError(f"Partition: overlap_m must be >= 0, got {self.overlap_m}")

    @classmethod
    def split_x(cls, region: Region, at: float, overlap_m: float) -> Partition:
        """Two regions of ``region``: west of ``x = at`` and east of it."""
        return cls((Region(region.xmin, at, region.ymin, region.ymax),
                    Region(at, region.xmax, region.ymin, region.ymax)), overlap_m)

    def __len__(self) -> int:
        return len(self.cores)

    def _inside(self, i: int, x: np.ndarray, y: np.ndarray, pad: float) -> np.ndarray:
        c = self.cores[i]
        return (x >= c.xmin - pad) & (x < c.xmax + pad) & (y >= c.ymin - pad) & \
            (y < c.ymax + pad)

    def in_core(self, i: int, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Mask of the points in region ``i``'s core (half-open: a point on a border
        belongs to one core)."""
        return self._inside(i, np.asarray(x, float), np.asarray(y, float), 0.0)

    def split(self, scan: Scan) -> list[Scan]:
        """Region ``i``'s part of ``scan``: the plots within its core widened by the
        overlap (the frame's index, time and plot rows kept; possibly no plot)."""
        x, y = scan.z[:, 0], scan.z[:, 1]
        out = []
        for i in range(len(self.cores)):
            keep = self._inside(i, x, y, self.overlap_m)
            out.append(dataclasses.replace(
                scan, z=scan.z[keep], sensor=scan.sensor[keep], rows=scan.rows[keep],
                R=None if scan.R is None else scan.R[keep],
                origin=None if scan.origin is None else scan.origin[keep],
                t=None if scan.t is None else scan.t[keep],
                attrs=None if scan.attrs is None else scan.attrs.take(keep)))
        return out


class RegionTracker:
    """One region's tracker (what one machine runs; a Dask actor in
    ``benchmarks/regions.py``): built there from its name, configuration and sensors
    (:func:`~mhtrack.build.make_tracker`: plain data travel, a tracker is made where it
    runs), steps its frames and returns their reports."""

    def __init__(self, name: str, config: MHTConfig, sensors: SensorSet | None = None
                 ) -> None:
        from mhtrack.build import make_tracker

        self.tracker = make_tracker(name, config, sensors=sensors)

    def step(self, frames: list[Scan]) -> TrackTable:
        """Step every frame in order; the confirmed tracks reported at each (online
        rows), concatenated. A frame without plots is skipped, as a source makes no frame
        without plots (the radar's look is known from its plots)."""
        parts = [self.tracker.step(f) for f in frames if len(f.rows)]
        parts = [p for p in parts if len(p)]
        return TrackTable.concat(parts) if parts else TrackTable.empty()


@dataclass
class _System:
    owner: int
    time: float
    state: np.ndarray  # x, y, vx, vy at ``time``, as the owner last reported
    linked: dict[int, int] = field(default_factory=dict)  # region -> its track id


class HandOver:
    """System track ids over regions (module docstring: matching and ownership)."""

    def __init__(self, partition: Partition, *, gate_m: float = GATE_M,
                 gate_v: float = GATE_V, max_age_s: float = MAX_AGE_S) -> None:
        self.partition = partition
        self.gate_m, self.gate_v, self.max_age_s = float(gate_m), float(gate_v), \
            float(max_age_s)
        self.systems: dict[int, _System] = {}
        self.link: dict[tuple[int, int], int] = {}  # (region, track id) -> system id
        self.seen: dict[tuple[int, int], float] = {}  # (region, track id) -> last report
        self.handovers = 0  # ownership moves between regions
        self._next = 1

    def assign(self, reports: list[TrackTable]) -> tuple[TrackTable, np.ndarray]:
        """The published rows of one batch of every region's reports (``reports[i]``:
        region ``i``'s rows, e.g. one window of frames) with their system ids as
        ``track_id``, in time order (then region), and the published rows' region."""
        rows = [(float(t), i, j) for i, r in enumerate(reports)
                for j, t in enumerate(r.time.tolist())]
        rows.sort()
        keep: list[tuple[int, int]] = []
        sids: list[int] = []
        for t, i, j in rows:
            r = reports[i]
            s = np.array([r.x[j], r.y[j], r.vx[j], r.vy[j]], float)
            sid = self._system_id(i, int(r.track_id[j]), t, s)
            if sid is not None:
                keep.append((i, j))
                sids.append(sid)
        if not keep:
            return TrackTable.empty(), np.zeros(0, np.int64)
        offset = np.cumsum([0] + [len(r) for r in reports])
        every = TrackTable.concat([r for r in reports if len(r)])
        out = every.take(np.array([offset[i] + j for i, j in keep], np.int64))
        return (dataclasses.replace(out, track_id=np.asarray(sids, np.int64)),
                np.array([i for i, _ in keep], np.int64))

    def _system_id(self, region: int, track: int, t: float, s: np.ndarray) -> int | None:
        """The system id of region ``region``'s track at time ``t`` with state ``s``
        (x, y, vx, vy), or None when it is not published."""
        core = bool(self.partition.in_core(region, s[0:1], s[1:2])[0])
        self.seen[(region, track)] = t
        sid = self.link.get((region, track))
        if sid is None:
            sid = self._match(region, t, s)
            if sid is None:
                if not core:
                    return None
                sid, self._next = self._next, self._next + 1
                self.systems[sid] = _System(region, t, s)
            self.link[(region, track)] = sid
            self.systems[sid].linked[region] = track
        sy = self.systems[sid]
        if sy.owner != region and (core or t - sy.time > self.max_age_s):
            sy.owner = region
            self.handovers += 1
            if sy.time >= t:  # the former owner published it at this very frame
                return None
        if sy.owner != region:
            return None
        sy.time, sy.state = t, s
        return sid

    def _match(self, region: int, t: float, s: np.ndarray) -> int | None:
        """The nearest system track owned by another region, without a track of
        ``region`` linked, recent and within the gates (module docstring, rule 2)."""
        best, best_d = None, self.gate_m
        for sid, sy in self.systems.items():
            if sy.owner == region or t - sy.time > self.max_age_s:
                continue
            mine = sy.linked.get(region)  # this region's track on it, if still reported
            if mine is not None and t - self.seen[(region, mine)] <= self.max_age_s:
                continue
            dt = t - sy.time
            px, py = sy.state[0] + sy.state[2] * dt, sy.state[1] + sy.state[3] * dt
            d = float(np.hypot(px - s[0], py - s[1]))
            if d <= best_d and np.hypot(*(sy.state[2:] - s[2:])) <= self.gate_v:
                best, best_d = sid, d
        return best
