"""Which sensors contributed to a track, and how long ago each last updated it (issue 29
item 5; the tracks file's ``sensors`` and ``sensor_ages``, after CAT062's I062/290
"system track update ages"): per track id, the time of the last plot of each sensor the
confirmed track used, remembered for
:attr:`~mhtrack.mht.attribute_scores.AttributeModel.resume_s`. The same store keeps the
time of the last plot of each technology (:data:`~mhtrack.attributes.TECHNOLOGIES`: PSR,
SSR, Mode S, by the plots' types) under the keys :data:`TECHNOLOGY_KEYS` (negative: no
sensor id is), for I062/290's per-technology ages."""

from __future__ import annotations

import numpy as np

from mhtrack.attributes import TECHNOLOGIES

#: The store's key of each technology (in :data:`~mhtrack.attributes.TECHNOLOGIES` order).
TECHNOLOGY_KEYS = {name: -1 - i for i, name in enumerate(TECHNOLOGIES)}


def technology_updates(track: np.ndarray, plot_type: np.ndarray, time: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(track, key, time)`` of the updates by plots of types ``plot_type``, one per
    technology the type counts for (a combined plot: PSR and SSR)."""
    ts, ks, ws = [], [], []
    for name, types in TECHNOLOGIES.items():
        m = np.isin(plot_type, types)
        ts.append(track[m])
        ks.append(np.full(int(m.sum()), TECHNOLOGY_KEYS[name], np.int64))
        ws.append(time[m])
    return np.concatenate(ts), np.concatenate(ks), np.concatenate(ws)


class SensorAges:
    """The last update time of each (track id, sensor) pair."""

    def __init__(self, memory_s: float) -> None:
        self.memory_s = float(memory_s)
        self.track = np.zeros(0, np.int64)
        self.sensor = np.zeros(0, np.int64)
        self.time = np.zeros(0)

    def update(self, track: np.ndarray, sensor: np.ndarray, time: np.ndarray,
               now: float) -> None:
        """Record updates of tracks ``track`` by plots of ``sensor`` at ``time``; keep
        the latest per pair; forget pairs older than the memory before ``now``."""
        t = np.concatenate((np.asarray(track, np.int64), self.track))
        s = np.concatenate((np.asarray(sensor, np.int64), self.sensor))
        w = np.concatenate((np.asarray(time, float), self.time))
        order = np.lexsort((-w, s, t))  # per pair, the latest first
        t, s, w = t[order], s[order], w[order]
        first = np.ones(t.size, bool)
        first[1:] = (t[1:] != t[:-1]) | (s[1:] != s[:-1])
        keep = first & (w >= now - self.memory_s)
        self.track, self.sensor, self.time = t[keep], s[keep], w[keep]

    def of(self, track: np.ndarray, at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per row (track id, time ``at``): its sensors in increasing id, as text
        ``"1;3"``, and their ages ``at − last update`` (s), as text ``"0.000;2.512"``
        (millisecond steps); ``""`` for a track no sensor has updated."""
        sensors, ages = [], []
        start = np.searchsorted(self.track, track, "left")
        stop = np.searchsorted(self.track, track, "right")
        for a, b, t in zip(start.tolist(), stop.tolist(), np.asarray(at, float).tolist(),
                           strict=True):
            mine = self.sensor[a:b] >= 0  # the technologies' keys are not sensors
            sensors.append(";".join(str(v) for v in self.sensor[a:b][mine].tolist()))
            ages.append(";".join(f"{max(t - w, 0.0):.3f}"
                                 for w in self.time[a:b][mine].tolist()))
        return np.array(sensors, object), np.array(ages, object)

    def technologies(self, track: np.ndarray, at: np.ndarray) -> np.ndarray:
        """Per row (track id, time ``at``) the age (s, ``at − last update``, at least 0)
        of each technology's last update, columns in
        :data:`~mhtrack.attributes.TECHNOLOGIES` order; NaN when none is known."""
        out = np.full((len(track), len(TECHNOLOGY_KEYS)), np.nan)
        at = np.asarray(at, float)
        for j, key in enumerate(TECHNOLOGY_KEYS.values()):
            m = self.sensor == key
            tr, w = self.track[m], self.time[m]  # sorted by track (one entry per track)
            if not tr.size:
                continue
            k = np.minimum(np.searchsorted(tr, track), tr.size - 1)
            hit = tr[k] == track
            out[hit, j] = np.maximum(at[hit] - w[k[hit]], 0.0)
        return out

    def arrays(self) -> dict[str, np.ndarray]:
        return {"track": self.track, "sensor": self.sensor, "time": self.time}

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """Restore :meth:`arrays` (none known when the state has none)."""
        if arrays:
            self.track = np.asarray(arrays["track"], np.int64)
            self.sensor = np.asarray(arrays["sensor"], np.int64)
            self.time = np.asarray(arrays["time"], float)
