"""What a reported track says besides its state (issue 29 item 5): the flight level and
rate of climb of its leaf's vertical state, its last validated Mode 3/A code, its Mode S
address, its latest callsign and its position's accuracy
(:class:`~mhtrack.attributes.TrackAttributes`), for the tracks file and CAT062.

* **Flight level, rate**: the leaf's vertical state (:mod:`mhtrack.mht.attribute_scores`)
  predicted to the row's time, ``ĥ = h + ḣ (t − t₀)`` (constant climb rate), ``ḣ`` in
  ft/min (``1 FL/s = 6 000 ft/min``); NaN before a validated level started it.
* **Code, address**: the leaf's ``ident`` (the last validated code, the first address).
* **Callsign**: the one the plot of this row carries, else the latest one a plot of the
  track carried within :attr:`~mhtrack.mht.attribute_scores.AttributeModel.resume_s`
  (:class:`Callsigns`); identification comes in Mode S replies only when the aircraft
  is interrogated for it (BDS 2,0), not with every plot.
* **Accuracy**: the position covariance's ellipse (:func:`~mhtrack.attributes.accuracy`).
* **Existence probability**: ``1/(1 + e^−L)`` of the leaf's score ``L``
  (:func:`~mhtrack.attributes.existence`).
* **Sensors**: those whose plots updated the confirmed track, with the age of each one's
  last update at the row's time (:class:`~mhtrack.mht.sensor_ages.SensorAges`), and the
  age of its last PSR, SSR and Mode S update (by the plots' types).
"""

from __future__ import annotations

import numpy as np

from mhtrack.attributes import (
    FPM_PER_FL_S,
    PlotAttributes,
    TrackAttributes,
    accuracy,
    existence,
)
from mhtrack.mht.attribute_scores import positions
from mhtrack.mht.sensor_ages import SensorAges, technology_updates
from mhtrack.mht.tree import Leaves


class Callsigns:
    """The latest callsign (text) of each track id and when it was last reported."""

    def __init__(self, memory_s: float) -> None:
        self.memory_s = float(memory_s)
        self.track = np.zeros(0, np.int64)
        self.callsign = np.zeros(0, "U8")
        self.time = np.zeros(0)

    def latest(self, track: np.ndarray, seen: np.ndarray, time: float) -> np.ndarray:
        """The callsign of each of ``track`` (ids): ``seen`` (text, ``""`` none) where
        given, else the remembered one (``""`` unknown); remembers the result at ``time``
        and forgets entries older than the memory."""
        seen = np.asarray(seen, dtype="U8")
        old = np.full(track.size, "", "U8")
        if self.track.size:
            k = np.minimum(np.searchsorted(self.track, track), self.track.size - 1)
            old = np.where(self.track[k] == track, self.callsign[k], old)
        out = np.where(seen != "", seen, old).astype("U8")
        has = out != ""
        ids = np.concatenate((track[has], self.track))
        names = np.concatenate((out[has], self.callsign))
        when = np.concatenate((np.full(int(has.sum()), float(time)), self.time))
        ids, first = np.unique(ids, return_index=True)  # the newest entry per id
        keep = when[first] >= time - self.memory_s
        self.track, self.callsign, self.time = ids[keep], names[first][keep], \
            when[first][keep]
        return out

    def arrays(self) -> dict[str, np.ndarray]:
        return {"track": self.track, "callsign": self.callsign, "time": self.time}

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """Restore :meth:`arrays` (none known when the state has none)."""
        if arrays:
            self.track = np.asarray(arrays["track"], np.int64)
            self.callsign = np.asarray(arrays["callsign"], "U8")
            self.time = np.asarray(arrays["time"], float)


def says_anything(attrs: PlotAttributes | None, leaves: Leaves) -> bool:
    """Whether a frame's tracks have attributes to report: its plots carry a code, a
    level or an address, or a leaf has one from earlier plots. Plots whose attribute
    columns are all empty (a recording of primary plots) report none: their tracks are
    written exactly as without the columns."""
    return attrs is not None and (attrs.any() or bool((leaves.ident >= 0).any())
                                  or bool(np.isfinite(leaves.level[:, 0]).any()))


def track_attributes(leaves: Leaves, sel: np.ndarray, attrs: PlotAttributes,
                     rows: np.ndarray, callsigns: Callsigns, time: float, *,
                     sensor: np.ndarray, plot_t: np.ndarray, ages: SensorAges
                     ) -> TrackAttributes:
    """The attributes (module docstring) of the reported leaves ``sel`` (in row order),
    from the frame's plots' ``attrs`` (row ids ``rows``, sensors ``sensor``, times
    ``plot_t``) at frame time ``time``."""
    t = leaves.time.take(sel)
    plot = leaves.window[:, -1].take(sel)
    j = positions(rows, plot) if rows.size else np.full(sel.size, -1)
    cs = attrs.callsign[np.maximum(j, 0)] if len(attrs) else np.full(sel.size, "", object)
    seen = np.array([str(c).strip() if k >= 0 else "" for c, k in
                     zip(cs.tolist(), j.tolist(), strict=True)], "U8")
    major, minor, orient = accuracy(leaves.P.take(sel, axis=0))
    tid = leaves.track.take(sel)
    hit = j >= 0
    upd = [(tid[hit], sensor[j[hit]], plot_t[j[hit]])]
    if len(attrs):
        upd.append(technology_updates(tid[hit], attrs.plot_type[j[hit]], plot_t[j[hit]]))
    ages.update(*(np.concatenate(c) for c in zip(*upd, strict=True)), time)  # once a report
    sensors, age = ages.of(tid, t)
    tech = ages.technologies(tid, t)
    return TrackAttributes(
        **identity(leaves.level.take(sel, axis=0), leaves.ident.take(sel, axis=0), t),
        callsign=callsigns.latest(leaves.track.take(sel), seen, time).astype(object),
        sigma_major=major, sigma_minor=minor, sigma_orient=orient, sensors=sensors,
        sensor_ages=age, age_psr=tech[:, 0], age_ssr=tech[:, 1], age_mds=tech[:, 2],
        **measured(attrs, j, sensor), existence_probability=existence(leaves.score.take(sel)))


def identity(level: np.ndarray, ident: np.ndarray, t: np.ndarray
             ) -> dict[str, np.ndarray]:
    """``flight_level``, ``rate_of_climb``, ``mode_3a`` and ``address`` (module docstring)
    of leaves with vertical states ``level`` and ``ident`` (rows of ``Leaves.level``,
    ``Leaves.ident``) at their times ``t``: ``ĥ = h + ḣ (t − t₀)``, ``ḣ`` in ft/min."""
    return {"flight_level": level[:, 0] + level[:, 1] * (t - level[:, 5]),
            "rate_of_climb": level[:, 1] * FPM_PER_FL_S, "mode_3a": ident[:, 0].copy(),
            "address": ident[:, 1].copy()}


def measured(attrs: PlotAttributes, j: np.ndarray, sensor: np.ndarray
             ) -> dict[str, np.ndarray]:
    """What the plots ``j`` (indices into the frame's plots, ``-1``: a miss) measured,
    as the ``meas_*`` columns of :class:`~mhtrack.attributes.TrackAttributes`."""
    hit = j >= 0
    k = np.maximum(j, 0)
    if not len(attrs):
        k = np.zeros(0, np.int64)
        hit = np.zeros(j.size, bool)

    def take(v: np.ndarray, absent: float | int) -> np.ndarray:
        return np.where(hit, v[k] if k.size else absent, absent)

    return {"meas_sensor": take(np.asarray(sensor, np.int64), -1),
            "meas_type": take(attrs.plot_type, 0),
            "meas_mode_3a": take(attrs.mode_3a, -1),
            "meas_mode_3a_vg": take(2 * attrs.mode_3a_v + attrs.mode_3a_g, 0),
            "meas_flight_level": take(attrs.flight_level, np.nan),
            "meas_flight_level_vg": take(2 * attrs.flight_level_v + attrs.flight_level_g, 0),
            "meas_range": take(attrs.polar_range, np.nan),
            "meas_bearing": _turn(take(attrs.polar_bearing, np.nan))}


def _turn(bearing: np.ndarray) -> np.ndarray:
    """Bearings in [0, 360): 360° (a reader accepts it; ``np.mod(-1e-17, 360)`` gives it)
    is north, 0°, as the tracks file requires."""
    return np.where(bearing >= 360.0, bearing - 360.0, bearing)
