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
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` for any writer (``np.savez``,
    ``pq.write_table``, ``Figure.savefig``, …); on success it replaces ``path``, on an
    exception it is removed and ``path`` is left as it was. The parent folder is created.
    The temporary name keeps ``path``'s suffix, for writers that choose a format by it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=path.suffix)
    os.close(fd)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def atomic_write(path: str | os.PathLike[str], data: bytes | str) -> Path:
    """Write ``data`` (text as UTF-8) to ``path`` atomically (see :func:`atomic_path`)."""
    if isinstance(data, str):
        data = data.encode("utf-8")
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())
    return Path(path)
