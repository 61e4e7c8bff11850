"""Sweep marks among the plots (``sectors=True``, ``docs/sources.md``, *Frames*): a
radar's CAT034/CAT002 north markers and sector crossings go through the re-order buffer
with its plots, as rows with ``mark`` true, so that the framer closes the radar's frame
when the antenna leaves its sector (:mod:`~mhtrack.sources.framer`)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

#: A chunk's columns: dtype and trailing shape of each.
Template = dict[str, tuple[np.dtype, tuple[int, ...]]]


def with_marks(out: dict[str, np.ndarray] | None,
               marks: list[tuple[float, int, int, int, int]],
               n0: int, template: Template | None) -> dict[str, np.ndarray]:
    """The converted plots ``out`` (``file_row`` from ``n0`` on, some left out) with the
    chunk's marks ``(time, radar, sector, j, offset)`` among them in arrival order — a
    mark decoded when the chunk held ``j`` plots goes before plot ``n0 + j``: rows with
    ``mark`` true, their ``time``, ``sensor``, ``sector`` (the radar's count of marks
    with this one) and ``offset`` (its data block's byte offset in the input: the
    datagram it came in, whose receive time the live status uses), ``file_row`` -1, the
    other columns of ``template`` blank (NaN, -1,
    empty). Without a template (no plot converted yet) the marks are left out: there is
    no frame they could close."""
    if template is None or not marks:
        return out if out is not None else {}
    m = len(marks)
    rows = {k: _blank(dt, (m, *shape)) for k, (dt, shape) in template.items()}
    rows["time"] = np.array([x[0] for x in marks], float)
    rows["sensor"] = np.array([x[1] for x in marks], np.int64)
    rows["sector"] = np.array([x[2] for x in marks], np.int64)
    rows["mark"] = np.ones(m, bool)
    rows["file_row"] = np.full(m, -1, np.int64)
    if "offset" in rows:
        rows["offset"] = np.array([x[4] for x in marks], rows["offset"].dtype)
    if out is None or not out["time"].size:
        return rows
    key = np.concatenate((2 * out["file_row"] + 1,
                          2 * (n0 + np.array([x[3] for x in marks], np.int64))))
    order = np.argsort(key, kind="stable")
    return {k: np.concatenate((out[k], rows[k]))[order] for k in out}


def template_of(cols: Mapping[str, np.ndarray] | None) -> Template | None:
    """The dtype and trailing shape of each column of ``cols`` (``None`` without rows):
    what :func:`with_marks` makes a mark's row of."""
    if cols is None or not len(cols["time"]):
        return None
    return {k: (np.asarray(v).dtype, np.shape(v)[1:]) for k, v in cols.items()}


def restored(pending: Mapping[str, Any] | None, sectors: bool
             ) -> tuple[dict[int, int], Template | None]:
    """From the rows an earlier stream held (``DatagramSource(pending=...)``): each
    radar's count of marks (a resumed run numbers its sectors on) and the template of the
    rows held but ``seq`` (the re-order buffer's arrival numbers, added on release): their
    frames are open, so a mark that comes before this run's first plot must close them
    (without a template such a mark would be left out: :func:`with_marks`). A
    ``ValueError`` if the rows were cut with their sectors (a ``sector`` column) and this
    stream is not (``sectors``), or the other way round: they cannot go on together."""
    if pending is None:
        return {}, None
    held = [pending.get(k) for k in ("held", "framed")]
    template = next((t for t in map(template_of, held) if t is not None), None)
    if template is not None:
        template.pop("seq", None)
        if ("sector" in template) != sectors:
            was, now = ("without", "with") if sectors else ("with", "without")
            raise ValueError(f"pending: rows held cut {was} their sectors, this stream's "
                             f"{now}")
    return dict(pending.get("marks") or {}), template


def row_place(row: dict[str, object]) -> str:
    """Where a row (its 1-d column values) is in the input of datagrams: ``byte N (plot
    k)`` — its data block's byte offset and decoding-order number —, ``byte N`` for a
    sweep mark (no plot)."""
    plot = "" if row.get("mark") else f" (plot {row['file_row']})"
    return f"byte {row['offset']}{plot}"


def _blank(dtype: np.dtype, shape: tuple[int, ...]) -> np.ndarray:
    """An array of ``shape`` meaning "none": NaN (floats), -1 (integers), ``""`` (text,
    also in an object column: the callsign's "absent"), else zeros (False)."""
    if dtype.kind == "f":
        return np.full(shape, np.nan, dtype)
    if dtype.kind in "iu":
        return np.full(shape, -1, dtype)
    if dtype.kind in "OUS":
        return np.full(shape, "", dtype)
    return np.zeros(shape, dtype)
