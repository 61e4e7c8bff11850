"""The tentative past of newly confirmed tracks (the *backfill*).

An MHT confirms a track only once its score passes the SPRT threshold, a few scans after
the target's first plot; until then the track is a tentative branch of its tree. A batch
user wants the track from its first plot (as Stone Soup's multi-measurement initiator
releases a track with its states since the first plot). This module keeps, for the last
``depth`` scans, the state of every tentative leaf and the id of the leaf it grew from
(``Leaves.node``, ``Leaves.parent``); when a tree is confirmed at scan ``k``, its chosen
leaf's ancestors give the track's states at the scans before ``k`` — exactly the filtered
states, plots and scores of the branch the confirmation decided on.

A backfilled row never takes a plot that the output already gives another track at that
scan (a track reported then, or an earlier backfill): the best hypothesis keeps plots apart
only within its N-scan window, so an older tentative past may reuse the plots of a track
that has since ended. The chain is cut at the first such scan; the track is then reported
from the scan after it.

Backfilled rows are *tentative*: at their scans the tracker had not yet decided that the
track is a target. When the plots had attributes, the log also keeps each tentative
leaf's code, address and vertical state and what its plot measured (``meas_*``, its
callsign), so that these rows carry the track's identity as it was at their scans, and
the callsign, sensors and ages of the chain's plots up to each row (:func:`carried`).
:attr:`mhtrack.records.TrackTable.tentative` marks them, so the online
view (``tentative == 0``) is always recoverable from a history output.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, fields, replace

import numpy as np

from mhtrack.attributes import TECHNOLOGIES, TrackAttributes, existence
from mhtrack.kernels import changes
from mhtrack.mht.attribute_scores import positions
from mhtrack.mht.track_attributes import identity, measured, says_anything
from mhtrack.mht.tree import Leaves
from mhtrack.records import Scan, TrackTable

#: The columns of what a logged leaf's plot measured
#: (:func:`~mhtrack.mht.track_attributes.measured`), integers among them :data:`_INT`.
MEASURED = ("meas_sensor", "meas_type", "meas_mode_3a", "meas_mode_3a_vg",
            "meas_flight_level", "meas_flight_level_vg", "meas_range", "meas_bearing")
_INT = {"meas_sensor", "meas_type", "meas_mode_3a", "meas_mode_3a_vg",
        "meas_flight_level_vg"}


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
    t: np.ndarray  # each leaf's own time
    #: the leaves' codes/addresses and vertical states (``Leaves.ident``, ``level``), only
    #: when some leaf has one (plots with attributes): ``None`` otherwise
    ident: np.ndarray | None = None
    level: np.ndarray | None = None
    #: what each leaf's plot at this scan measured (:data:`MEASURED` columns, NaN/absent
    #: codes on a miss) and the callsign it carried (``""`` none); with ``ident`` only
    meas: np.ndarray | None = None
    callsign: np.ndarray | None = None
    #: each model's filtered state (kept for the smoother only: ``models``)
    mu: np.ndarray | None = None
    xm: np.ndarray | None = None
    Pm: np.ndarray | None = None

    @classmethod
    def of(cls, scan: int, time: float, leaves: Leaves,
           rows: np.ndarray | None = None, models: bool = False,
           plots: Scan | None = None) -> _Logged:
        tentative = leaves.track < 0
        sel = (tentative if rows is None else tentative & rows).nonzero()[0]
        node = leaves.node[sel]
        if node.size > 1 and np.count_nonzero(node[1:] <= node[:-1]):
            sel = sel[node.argsort(kind="stable")]
            node = leaves.node[sel]
        # 2-D and wider rows by take (a copy without fancy indexing's set-up)
        ident = leaves.ident.take(sel, axis=0)
        level = leaves.level.take(sel, axis=0)
        known = bool((ident >= 0).any() or np.isfinite(level[:, 0]).any())
        m = (leaves.mu.take(sel, axis=0), leaves.xm.take(sel, axis=0),
             leaves.Pm.take(sel, axis=0)) if models else (None, None, None)
        plot = leaves.window[:, -1][sel]
        meas = callsign = None
        # what the plots measured whenever the frame's tracks report attributes (the
        # tracker's rule), whether a tentative leaf has an identity or not
        if plots is not None and says_anything(plots.attrs, leaves):
            j = positions(plots.rows, plot) if len(plots) else np.full(plot.size, -1)
            got = measured(plots.attrs, j, plots.sensor)
            meas = np.column_stack([got[k] for k in MEASURED]).astype(float)
            cs = plots.attrs.callsign[np.maximum(j, 0)] if len(plots) else np.full(j.size, "")
            callsign = np.where(j >= 0, cs, "").astype("U8")  # stripped when backfilled
        return cls(np.array([scan], np.int64), np.array([time], float), node,
                   leaves.parent[sel], leaves.x.take(sel, axis=0), leaves.P.take(sel, axis=0),
                   plot, leaves.score[sel], leaves.time[sel],
                   ident if known else None, level if known else None, meas, callsign, *m)

    def attributes(self, j: np.ndarray) -> TrackAttributes | None:
        """The identity of logged leaves ``j`` at their own times (code, address, flight
        level and rate of their vertical state, as :mod:`mhtrack.mht.track_attributes`
        reports a track; the accuracy of their covariance and the existence probability
        of their score), ``None`` when none was
        logged. Logged with the plots' attributes (``meas``) or an identity: each part
        logged, the existence probability always."""
        known = self.ident is not None and self.level is not None
        if not known and self.meas is None:
            return None
        meas = {} if self.meas is None or self.callsign is None else {
            "callsign": np.char.strip(self.callsign[j]).astype(object),
            **{k: self.meas[j, i].astype(np.int64 if k in _INT else float)
               for i, k in enumerate(MEASURED)}}
        ident = identity(self.level.take(j, axis=0), self.ident.take(j, axis=0),  # type: ignore[union-attr]
                         self.t[j]) if known else {}
        return replace(TrackAttributes.absent(j.size, self.P.take(j, axis=0)), **ident,
                       existence_probability=existence(self.score[j]), **meas)


class TentativeHistory:
    """States of tentative leaves over the last ``depth`` scans (0: keep nothing).

    Call :meth:`record` once per scan after the track management, and :meth:`backfill`
    before it for the leaves confirmed at that scan. ``models``: keep each leaf's model
    states too (an IMM's ``mu, xm, Pm``), for the rows' smoothing.
    """

    def __init__(self, depth: int, models: bool = False) -> None:
        if depth < 0:
            raise ValueError(f"history depth must be >= 0, got {depth}")
        self.depth = int(depth)
        self.models = models
        self._log: deque[_Logged] = deque(maxlen=max(self.depth, 1))
        #: per logged scan, the sorted plot rows the output gives a track at that scan
        self._claimed: deque[np.ndarray] = deque(maxlen=max(self.depth, 1))

    def record(self, scan: int, time: float, leaves: Leaves,
               rows: np.ndarray | None = None, rep: np.ndarray | None = None,
               plots: Scan | None = None) -> None:
        """Keep the tentative leaves (``track < 0``) of this scan, and the plots of the
        tracks reported at it (:meth:`Leaves.reported`; ``rep``: that mask, when known,
        not modified); ``rows`` (mask): of those leaves only (the leaves a frame
        stepped), as if given ``leaves.take(rows)``; ``plots``: the frame's plots, whose
        attributes give what each leaf's plot measured."""
        if self.depth:
            self._log.append(_Logged.of(scan, time, leaves, rows, self.models, plots))
            rep = leaves.reported() if rep is None else rep
            if rows is not None:
                rep = rep & rows
            used = np.sort(leaves.window[:, -1][rep])
            used = used[used >= 0]
            self._claimed.append(used[changes(used)])  # np.unique, without its set-up

    def backfill(self, leaves: Leaves, rows: np.ndarray) -> TrackTable:
        """The ancestors of leaves ``rows`` (just confirmed, ``track >= 0``) at the logged
        scans, as track rows with their track ids, ordered by scan then track id, all
        marked tentative. Walks each parent link one logged scan back at a time; a chain
        ends at its tree's root, at the oldest logged scan, or before a scan where its plot
        is already another track's in the output (several new tracks claiming one plot:
        the lower track id keeps it)."""
        rows = np.asarray(rows, np.int64)
        if not self.depth or rows.size == 0 or not self._log:
            return TrackTable.empty()
        cur = leaves.parent[rows]
        tid = leaves.track[rows]
        parts: list[TrackTable] = []
        for i in range(len(self._log) - 1, -1, -1):
            log = self._log[i]
            if cur.size == 0:
                break  # every chain has ended
            if log.node.size == 0:
                continue
            j = np.minimum(log.node.searchsorted(cur), log.node.size - 1)
            found = log.node[j] == cur
            # a leaf a frame did not step is logged at an older frame: look further back
            wait_cur, wait_tid = cur[~found], tid[~found]
            j, tid = j[found], tid[found]
            plot = log.plot[j]
            ok = (plot < 0) | ~np.isin(plot, self._claimed[i])
            order = np.lexsort((tid, plot))  # a plot two new chains share: lower id keeps it
            ps = plot[order]
            dup = np.zeros(plot.size, bool)
            dup[order[1:]] = (ps[1:] == ps[:-1]) & (ps[1:] >= 0)
            ok &= ~dup
            j, tid, plot = j[ok], tid[ok], plot[ok]
            self._claimed[i] = np.union1d(self._claimed[i], plot[plot >= 0])
            x = log.x.take(j, axis=0)
            n = j.size
            parts.append(TrackTable(
                scan=np.repeat(log.scan, n), time=log.t[j], track_id=tid,
                x=x[:, 0].copy(), y=x[:, 2].copy(), vx=x[:, 1].copy(), vy=x[:, 3].copy(),
                plot=plot, score=log.score[j], P=log.P.take(j, axis=0),
                tentative=np.ones(n, bool), attrs=log.attributes(j),
                **_models(log, j)))
            cur = log.parent[j]
            live = cur >= 0
            cur, tid = cur[live], tid[live]
            if wait_cur.size:
                cur, tid = np.concatenate((cur, wait_cur)), np.concatenate((tid, wait_tid))
        parts.reverse()
        return carried(TrackTable.concat(parts).sorted())

    # ------------------------------------------------------------- persistence
    def arrays(self) -> dict[str, np.ndarray]:
        """The log as flat arrays (for :meth:`MHTTracker.save`)."""
        out: dict[str, np.ndarray] = {"count": np.array([len(self._log)], np.int64)}
        for i, (log, claimed) in enumerate(zip(self._log, self._claimed, strict=True)):
            for f in fields(_Logged):
                if getattr(log, f.name) is not None:
                    out[f"{i}__{f.name}"] = getattr(log, f.name)
            out[f"{i}__claimed"] = claimed
        return out

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """Restore what :meth:`arrays` wrote."""
        self._log.clear()
        self._claimed.clear()
        for i in range(int(arrays["count"][0]) if "count" in arrays else 0):
            got = {f.name: np.asarray(arrays[f"{i}__{f.name}"]) for f in fields(_Logged)
                   if f"{i}__{f.name}" in arrays}
            got.setdefault("t", np.full(got["node"].size, float(got["time"][0])))
            self._log.append(_Logged(**got))
            self._claimed.append(np.asarray(arrays[f"{i}__claimed"], np.int64))


def carried(past: TrackTable) -> TrackTable:
    """``past`` (a backfill, by scan then track id) with each row's callsign, sensors and
    their ages, and the technologies' ages, as :mod:`mhtrack.mht.track_attributes`
    reports a confirmed track, from the plots of the track's own chain up to that row:
    the callsign of the latest plot that carried one, each sensor's (each technology's)
    latest plot time against the row's time."""
    a = past.attrs
    if a is None or not (a.meas_sensor >= 0).any():
        return past
    sensors, ages = a.sensors.copy(), a.sensor_ages.copy()
    callsign, tech = a.callsign.copy(), np.full((len(past), len(TECHNOLOGIES)), np.nan)
    for tid in np.unique(past.track_id).tolist():
        last: dict[int, float] = {}
        when: dict[int, float] = {}
        name = ""
        for r in np.flatnonzero(past.track_id == tid).tolist():  # in time order
            t = float(past.time[r])
            if a.meas_sensor[r] >= 0:
                last[int(a.meas_sensor[r])] = t
                for k, types in enumerate(TECHNOLOGIES.values()):
                    if a.meas_type[r] in types:
                        when[k] = t
            name = str(callsign[r]) or name
            callsign[r] = name
            sensors[r] = ";".join(str(s) for s in sorted(last))
            ages[r] = ";".join(f"{max(t - last[s], 0.0):.3f}" for s in sorted(last))
            for k, w in when.items():
                tech[r, k] = max(t - w, 0.0)
    return replace(past, attrs=replace(a, callsign=callsign, sensors=sensors,
                                       sensor_ages=ages, age_psr=tech[:, 0],
                                       age_ssr=tech[:, 1], age_mds=tech[:, 2]))


def _models(log: _Logged, j: np.ndarray) -> dict[str, np.ndarray]:
    """The model states of rows ``j`` of ``log`` as :class:`TrackTable` fields (none when
    the log kept none: a log restored from a state saved without them)."""
    if log.mu is None or log.xm is None or log.Pm is None:
        return {}
    return {"mu": log.mu.take(j, axis=0), "xm": log.xm.take(j, axis=0),
            "Pm": log.Pm.take(j, axis=0)}
