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

A recording without CAT062 but with **ADS-B reports** (CAT021) is read as the aircraft's
own reports instead (issue 28: ADS-B as the reference): key = the 24-bit target address
(I021/080), else 2²⁴ + station · 65 536 + the ground station's track number (I021/161);
velocity 0 (the reference is sampled between reports, never extrapolated); reports
flagged simulated, test or field monitor (I021/040 SIM, TST, RAB) are left out and
counted, as are reports with no identity.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.timeaxis import DAY_S

if TYPE_CHECKING:
    from mhtrack.io.asterix.category_file import Walked
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
    """The CAT062 updates of recording ``path`` — or, without CAT062, its CAT021 ADS-B
    reports (module docstring); the records skipped are in ``problems`` (the caller
    warns: one line per kind, naming ``path`` and the byte offset of the first)."""
    from mhtrack.io.asterix.cat062 import block062, track_columns
    from mhtrack.io.asterix.category_file import category_blocks, category_rows

    walked = category_blocks(path, (62, 21))  # one walk serves both categories
    rows, problems = category_rows(path, 62, block062, walked)
    if rows:
        cols = track_columns(rows)
        source = cols["sac"].astype(np.int64) * 256 + cols["sic"].astype(np.int64)
        key = source * 65536 + cols["track_number"].astype(np.int64)
        velocity = tuple(np.nan_to_num(np.asarray(cols[k], float)) for k in ("vx", "vy"))
    else:
        cols, key, problems = _adsb_reports(path, walked)
        velocity = (np.zeros(key.size), np.zeros(key.size))
    if frame is None:
        from mhtrack.models.geodesy import LocalFrame

        frame = LocalFrame(float(cols["lat"][0]), float(cols["lon"][0]))
    x, y = frame.to_local(cols["lat"], cols["lon"])
    vx, vy = frame.velocity_to_local(cols["lat"], cols["lon"], *velocity)
    state = np.column_stack([np.asarray(v, float) for v in (x, y, vx, vy)])
    return ReferenceUpdates(np.asarray(cols["time"], float), key, state, frame, problems)


def _adsb_reports(path: str | Path, walked: Walked | None = None
                  ) -> tuple[dict[str, np.ndarray], np.ndarray, Problems]:
    """The CAT021 reports of ``path`` (``walked``: already walked by
    :func:`~mhtrack.io.asterix.category_file.category_blocks`) as reference updates:
    columns ``time`` (continued across midnight), ``lat``, ``lon``; their keys; the
    parts skipped."""
    from mhtrack.errors import InputError
    from mhtrack.io.asterix.cat021 import COLUMNS, block021
    from mhtrack.io.asterix.category_file import category_rows
    from mhtrack.io.asterix.notplots import real_plots
    from mhtrack.io.asterix.timeaxis import unwrap_days

    at: list[int] = []

    def rows_of(raw: bytes, offset: int, problems: Problems) -> list[tuple[object, ...]] | None:
        found = block021(raw, offset, problems)
        if found is not None:
            at.extend([offset] * len(found))
        return found

    rows, problems = category_rows(path, 21, rows_of, walked)
    if not rows:
        raise InputError(f"{path}: no CAT062 track nor CAT021 ADS-B report with a position "
                         "and a time: not a reference", file=str(path))
    c = {k: np.array(v) for k, v in zip(COLUMNS, zip(*rows, strict=True), strict=True)}
    where = np.asarray(at, np.int64)
    real, _ = real_plots(np.full(where.size, -1), c["sim"], c["rab"], c["tst"])
    _count(problems, "not_plot", where, ~real)
    address = np.array([int(a, 16) if a else -1 for a in c["address"].tolist()], np.int64)
    tn = c["track_number"].astype(np.int64)
    key = np.where(address >= 0, address,
                   np.where(tn >= 0, 2**24 + c["sensor"].astype(np.int64) * 65536 + tn, -1))
    _count(problems, "no_identity", where, real & (key < 0))
    keep = real & (key >= 0)
    if not keep.any():
        raise InputError(f"{path}: no CAT021 ADS-B report of an aircraft with an address "
                         "or a track number: not a reference", file=str(path))
    cols = {"time": unwrap_days(c["time"][keep].astype(float)),
            "lat": c["lat"][keep].astype(float), "lon": c["lon"][keep].astype(float)}
    return cols, key[keep], problems


def _count(problems: Problems, kind: str, where: np.ndarray, mask: np.ndarray) -> None:
    """Count the reports of ``mask`` as ``kind``, the first at its byte offset."""
    if mask.any():
        problems.add(kind, int(where[mask][0]), int(np.count_nonzero(mask)))
