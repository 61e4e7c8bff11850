"""Input and output paths, checked before any work: nothing computed is lost to a bad
``--out``, no input is ever overwritten by an output, and no reader blocks on a FIFO.

:func:`check_output_file` and :func:`check_output_dir` raise :class:`InputError` with one
line naming the path and what is wrong; the commands call them before reading or
computing anything. :func:`check_input_file` is called by every reader before it opens a
file: an input must be a regular file (a FIFO, a device or a socket is refused, not read
with a timeout — refusing is deterministic and never hangs).
"""

from __future__ import annotations

import contextlib
import os
import stat
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import BinaryIO

from mhtrack.errors import InputError

#: File extensions of the tables mhtrack writes.
TABLE_SUFFIXES = (".csv", ".parquet")


def check_input_file(path: str | os.PathLike[str]) -> Path:
    """``path`` names an existing regular file (symbolic links followed) that can be
    opened for reading; else :class:`InputError` ``<path>: <what it is instead>``."""
    name = str(path)
    p = Path(path)
    try:
        mode = p.stat().st_mode
    except FileNotFoundError:
        raise InputError(f"{name}: no such file", file=name) from None
    except OSError as e:
        raise InputError(f"{name}: cannot read ({e.strerror or e})", file=name) from None
    if stat.S_ISDIR(mode):
        raise InputError(f"{name}: is a directory, not a file", file=name)
    if not stat.S_ISREG(mode):
        kind = ("a FIFO (named pipe)" if stat.S_ISFIFO(mode) else
                "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else
                "a socket" if stat.S_ISSOCK(mode) else "not a regular file")
        raise InputError(f"{name}: is {kind}, not a regular file (inputs are read from "
                         "regular files only)", file=name)
    if not os.access(p, os.R_OK):
        raise InputError(f"{name}: cannot read (permission denied)", file=name)
    return p


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


def _name_fits(path: Path, what: str) -> None:
    """The last part of ``path`` fits the file system's name limit (``NAME_MAX``, 255 bytes
    on most), so that nothing computed is lost to a name refused at the end. The atomic
    writer's temporary names are at most 49 bytes (:mod:`mhtrack.io.atomic`): any name
    that fits is written."""
    try:
        limit = os.pathconf(_nearest_existing(path.absolute().parent), "PC_NAME_MAX")
    except (OSError, ValueError, AttributeError):
        limit = 255
    n = len(os.fsencode(path.name))
    if n > limit:
        raise InputError(f"{path}: cannot write the {what}: its name is {n} bytes long, the "
                         f"file system allows {limit}", file=str(path))


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
    _name_fits(path, what)
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
    _name_fits(path, what)
    if path.exists() and not path.is_dir():
        raise InputError(f"{path}: is a file, not a folder for the {what}", file=str(path))
    for inp in inputs:
        if inp is not None and _same_file(path, Path(inp)):
            raise InputError(f"{path}: the {what} folder is the input {inp}; choose another "
                             f"{option}", file=str(path))
    _writable_folder(path, what)


@contextlib.contextmanager
def arrow_file(path: str | os.PathLike[str], mode: str = "rb") -> Iterator[str | BinaryIO]:
    """``path`` for pyarrow: its text when it is UTF-8 (pyarrow's own reader), else an open
    Python file (pyarrow refuses names that are not UTF-8, which Python keeps as surrogate
    escapes; the OS takes the bytes as they are)."""
    name = os.fspath(path)
    try:
        name.encode("utf-8")
    except UnicodeEncodeError:
        with open(name, mode) as fh:
            yield fh
        return
    yield name
