"""Which sensors contributed to a track, and how long ago each last updated it (issue 29
item 5; the tracks file's ``sensors`` and ``sensor_ages``, after CAT062's I062/290
"system track update ages"): per track id, the time of the last plot of each sensor the
confirmed track used, remembered for
:attr:`~mhtrack.mht.attribute_scores.AttributeModel.resume_s`."""

from __future__ import annotations

import numpy as np


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
            sensors.append(";".join(str(v) for v in self.sensor[a:b].tolist()))
            ages.append(";".join(f"{max(t - w, 0.0):.3f}" for w in self.time[a:b].tolist()))
        return np.array(sensors, object), np.array(ages, object)

    def arrays(self) -> dict[str, np.ndarray]:
        return {"track": self.track, "sensor": self.sensor, "time": self.time}

    def set_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        """Restore :meth:`arrays` (none known when the state has none)."""
        if arrays:
            self.track = np.asarray(arrays["track"], np.int64)
            self.sensor = np.asarray(arrays["sensor"], np.int64)
            self.time = np.asarray(arrays["time"], float)
