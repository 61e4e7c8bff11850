"""Atomic file output: every file mhtrack writes appears whole or not at all.

A writer writes to a temporary file in the destination's own folder, flushed to disk,
then ``os.replace`` moves it onto the destination (atomic on POSIX and Windows within one
file system), so an interruption or a concurrent reader never sees half a file, and an
existing file is only replaced by a complete new one.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str], *, make_parent: bool = True) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` for any writer (``np.savez``,
    ``pq.write_table``, ``Figure.savefig``, …); on success it is flushed to disk (fsync) and
    replaces ``path``, on an exception it is removed and ``path`` is left as it was. The
    parent folder is created (``make_parent``; else a missing one raises
    ``FileNotFoundError``). The temporary name keeps ``path``'s suffix, for writers that
    choose a format by it. The new file gets the permissions an ordinary ``open(path, "w")``
    would give (``0o666`` less the umask), not ``mkstemp``'s owner-only ``0o600``."""
    path = Path(path)
    if make_parent:
        path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=path.suffix)
    os.close(fd)
    try:
        yield Path(tmp)
        _fsync(tmp)
        os.chmod(tmp, _default_mode())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _fsync(path: str) -> None:
    """Flush ``path``'s data to disk (the writer has closed it)."""
    with open(path, "rb+") as fh:
        os.fsync(fh.fileno())


def _default_mode() -> int:
    """``0o666`` less the process umask: the mode ``open(path, "w")`` gives a new file."""
    umask = os.umask(0o022)
    os.umask(umask)
    return 0o666 & ~umask


def atomic_write(path: str | os.PathLike[str], data: bytes | str, *,
                 make_parent: bool = True) -> Path:
    """Write ``data`` (text as UTF-8) to ``path`` atomically (see :func:`atomic_path`)."""
    if isinstance(data, str):
        data = data.encode("utf-8")
    with atomic_path(path, make_parent=make_parent) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
    return Path(path)
