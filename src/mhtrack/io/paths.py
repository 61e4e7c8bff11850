"""Output paths, checked before any work: nothing computed is lost to a bad ``--out``, and
no input is ever overwritten by an output.

:func:`check_output_file` and :func:`check_output_dir` raise :class:`InputError` with one
line naming the path and what is wrong; the commands call them before reading or
computing anything.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from mhtrack.errors import InputError

#: File extensions of the tables mhtrack writes.
TABLE_SUFFIXES = (".csv", ".parquet")


def _nearest_existing(path: Path) -> Path:
    p = path.absolute()
    while not p.exists() and p != p.parent:
        p = p.parent
    return p


def _writable_folder(path: Path, what: str) -> None:
    folder = _nearest_existing(path)
    if not folder.is_dir():
        raise InputError(f"{path}: cannot write the {what} there: {folder} is not a folder",
                         file=str(path))
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(f"{path}: cannot write the {what}: folder {folder} is not writable",
                         file=str(path))


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.resolve() == b.resolve() or (a.exists() and b.exists() and a.samefile(b))
    except OSError:
        return False


def check_output_file(path: Path, *, inputs: Iterable[Path | None] = (),
                      suffixes: tuple[str, ...] = TABLE_SUFFIXES, what: str = "output",
                      option: str = "--out") -> None:
    """``path`` may be written: its extension is one of ``suffixes``, it is none of the
    ``inputs``, and its folder exists and is writable."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise InputError(f"{path}: unknown extension {path.suffix or '(none)'!r} for the "
                         f"{what} (expected {', '.join(suffixes)})", file=str(path))
    for inp in inputs:
        if inp is not None and _same_file(path, Path(inp)):
            raise InputError(f"{path}: the {what} is the input file {inp}; choose another "
                             f"{option}", file=str(path))
    if path.is_dir():
        raise InputError(f"{path}: is a folder, not a file", file=str(path))
    parent = path.absolute().parent
    if not parent.is_dir():  # the table writers do not create folders
        raise InputError(f"{path}: cannot write the {what}: folder {parent} does not exist",
                         file=str(path))
    _writable_folder(parent, what)


def check_output_dir(path: Path, *, inputs: Iterable[Path | None] = (),
                     what: str = "outputs", option: str = "--out") -> None:
    """``path`` may hold written files: it is not a file, holds none of the ``inputs``'
    names as the files it will write over, and is (or can be created) writable."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(f"{path}: is a file, not a folder for the {what}", file=str(path))
    for inp in inputs:
        if inp is not None and _same_file(path, Path(inp)):
            raise InputError(f"{path}: the {what} folder is the input {inp}; choose another "
                             f"{option}", file=str(path))
    _writable_folder(path, what)
