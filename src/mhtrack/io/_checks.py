"""Row-order checks shared by the plots, truth and tracks tables: scans in order, one
time per scan, times increasing, no id twice in a scan — each error located by line/row."""

from __future__ import annotations

import numpy as np

from mhtrack.io._frame import Frame


def num(v: object) -> str:
    """A number for a message: integers as digits, floats in shortest round-trip form."""
    if isinstance(v, np.integer | int):
        return str(int(v))
    return repr(float(v))  # type: ignore[arg-type]


def check_scan_order(frame: Frame, scan: np.ndarray, time: np.ndarray) -> None:
    """Scans non-decreasing; one time per scan; times never going back from scan to scan."""
    if scan.size < 2:
        return
    src = frame.src
    after = np.concatenate(([False], scan[1:] < scan[:-1]))  # no np.diff: int64 overflow
    frame.check(
        after,
        "scan",
        lambda r: (
            f"scan {num(scan[r])} after scan {num(scan[r - 1])} ({src.where(r - 1)}); "
            "rows must be in non-decreasing scan order"
        ),
    )
    same = np.concatenate(([False], scan[1:] == scan[:-1]))
    changed = np.concatenate(([False], time[1:] != time[:-1]))
    back = np.concatenate(([False], time[1:] < time[:-1]))
    first = np.maximum.accumulate(np.where(same, 0, np.arange(scan.size)))

    def differs(r: int) -> str:
        f = int(first[r])
        return (
            f"time {num(time[r])} differs from time {num(time[f])} of scan {num(scan[r])} on "
            f"{src.where(f)}; all rows of a scan must have the same time"
        )

    frame.check(same & changed, "time", differs)
    frame.check(
        ~same & back,
        "time",
        lambda r: (
            f"time goes backwards: {num(time[r])} at scan {num(scan[r])} after "
            f"{num(time[r - 1])} at scan {num(scan[r - 1])} ({src.where(r - 1)})"
        ),
    )
    frame.check(
        ~same & ~changed & (np.arange(scan.size) > 0),
        "time",
        lambda r: (
            f"scan {num(scan[r])} has time {num(time[r])} s, not after scan "
            f"{num(scan[r - 1])}'s ({src.where(r - 1)}); times must strictly increase "
            "with scan number"
        ),
    )


def check_unique(frame: Frame, scan: np.ndarray, ids: np.ndarray, column: str) -> None:
    """No id twice within one scan (``scan`` already known to be sorted)."""
    if ids.size < 2:
        return
    order = np.lexsort((np.arange(ids.size), ids, scan))
    s, i = scan[order], ids[order]
    dup = (s[1:] == s[:-1]) & (i[1:] == i[:-1])
    rows = np.flatnonzero(dup)
    if rows.size:
        k = rows[np.argmin(order[rows + 1])]  # lexsort keeps file order among equal keys
        earlier, later = int(order[k]), int(order[k + 1])
        raise frame.src.error(
            f"{column} {num(ids[later])} appears twice in scan {num(scan[later])} "
            f"(also on {frame.src.where(earlier)})",
            row=later,
            column=column,
        )
