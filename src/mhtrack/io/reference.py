"""A reference system's tracks, recorded as ASTERIX CAT062, read as the updates that
``mhtrack evaluate TRACKS --reference REC`` takes for the truth
(:mod:`mhtrack.metrics.reference` samples them; docs/metrics.md, "A reference system as
the truth").

From the recording (:func:`~mhtrack.io.asterix.cat062.read_system_tracks`: physically
impossible records — |lat| > 90°, |lon| > 180°, a time of day ≥ 86 400 s — refused and
counted in ``problems``, never passed on):

* **key** of each update: its data source (I062/010, SAC·256 + SIC) · 65 536 + its track
  number (I062/040);
* **frame**: WGS-84 ``lat, lon`` to the local plane by ``frame.to_local`` (without one:
  the plane about the first update's position), east/north velocities by
  ``frame.velocity_to_local`` (I062/185 absent: 0);
* **days**: CAT062 gives times of day (continued across midnight);
  :meth:`ReferenceUpdates.near` moves them by the whole number of days that brings the
  first one nearest to our tracks' first time.

Tentative (I062/080 CNF) and coasting (CST) updates are kept: they are states the
reference system reported.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.timeaxis import DAY_S

if TYPE_CHECKING:
    from mhtrack.models.geodesy import LocalFrame


@dataclass(frozen=True)
class ReferenceUpdates:
    """A reference system's track updates in the local ``frame``: ``time`` (s), ``key``
    (source · 65 536 + track number), ``state`` ``(n, 4)`` = ``x, y, vx, vy``; the whole
    ``days`` the times were moved by and the records skipped (``problems``)."""

    time: np.ndarray
    key: np.ndarray
    state: np.ndarray
    frame: LocalFrame
    problems: Problems
    days: int = 0

    def __len__(self) -> int:
        return int(self.time.size)

    def near(self, t: float) -> ReferenceUpdates:
        """Moved by the whole number of days that brings the first update nearest to
        ``t`` (CAT062 times are times of day)."""
        if len(self) == 0 or not np.isfinite(t):
            return self
        days = int(np.round((t - float(self.time.min())) / DAY_S))
        if days == 0:
            return self
        return replace(self, time=self.time + days * DAY_S, days=self.days + days)


def read_reference(path: str | Path, frame: LocalFrame | None = None) -> ReferenceUpdates:
    """The CAT062 updates of recording ``path`` (module docstring); the records skipped
    are in ``problems`` (the caller warns: one line per kind, naming ``path`` and the
    byte offset of the first)."""
    from mhtrack.io.asterix.cat062 import read_system_tracks

    cols, problems = read_system_tracks(path)
    if frame is None:
        from mhtrack.models.geodesy import LocalFrame

        frame = LocalFrame(float(cols["lat"][0]), float(cols["lon"][0]))
    source = cols["sac"].astype(np.int64) * 256 + cols["sic"].astype(np.int64)
    key = source * 65536 + cols["track_number"].astype(np.int64)
    x, y = frame.to_local(cols["lat"], cols["lon"])
    ve, vn = (np.nan_to_num(np.asarray(cols[k], float)) for k in ("vx", "vy"))
    vx, vy = frame.velocity_to_local(cols["lat"], cols["lon"], ve, vn)
    state = np.column_stack([np.asarray(v, float) for v in (x, y, vx, vy)])
    return ReferenceUpdates(np.asarray(cols["time"], float), key, state, frame, problems)
