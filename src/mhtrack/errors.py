"""The one exception raised for bad input files.

Every reader in :mod:`mhtrack.io`, and every other boundary that reads user input, turns a
problem with a user's file into an :class:`InputError` whose message says where the
problem is, in the form::

    plots.csv, line 17, column 'x': value 'nan' is not finite
    plots.parquet, row 15 (0-based), column 'x': value 'nan' is not finite
    plots.csv: missing required column(s) 'y'
    scenario.toml, line 3, column 9: Expected '=' after a key in a key/value pair
    scenario.toml: targets[2].birth: must be <= death (50 > 40)

CSV line numbers are those a text editor shows (the header is line 1); Parquet rows are
0-based, the same indices that the ``plot`` column of a tracks file uses. The CLI catches
:class:`InputError` and prints its message instead of a traceback.

This module imports nothing from mhtrack, so any layer may import it cheaply.
"""

from __future__ import annotations


def short_number(x: float) -> str:
    """Short form of a limit or a count in messages: ``1e6``, ``30``, ``5e7``, ``2.5e4``
    (``inf``, ``nan`` as such)."""
    if x != x or abs(x) == float("inf"):
        return str(float(x))
    if abs(x) >= 1e4:
        m, e = f"{x:.6e}".split("e")
        return f"{m.rstrip('0').rstrip('.')}e{int(e)}"
    return f"{x:g}"


def printable(text: object) -> str:
    """``text`` (a message or a path) as text any stream can print: the bytes of a file
    name that are not UTF-8 (which Python keeps as surrogate escapes, PEP 383) shown as
    ``\\xNN``; everything else unchanged."""
    s = text.decode("utf-8", "surrogateescape") if isinstance(text, bytes) else str(text)
    return s.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")


class InputError(ValueError):
    """A user-supplied file (or path) is missing, unreadable or malformed.

    Parameters
    ----------
    message : the full message, already naming the file and the place.
    file : the path as the user gave it.
    line : 1-based CSV line, or TOML line (``None`` when not about one line).
    row : 0-based data-row index (CSV and Parquet), when about one row.
    column : the CSV/Parquet column name, when about one column.
    key : the key path in a TOML file (``targets[2].birth``), when about one key.
    """

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        line: int | None = None,
        row: int | None = None,
        column: str | None = None,
        key: str | None = None,
    ) -> None:
        super().__init__(printable(message))
        self.file = file
        self.line = line
        self.row = row
        self.column = column
        self.key = key
