"""Atomic file output: every file mhtrack writes appears whole or not at all.

A writer writes to a temporary file in the destination's own folder, flushed to disk,
then ``os.replace`` moves it onto the destination (atomic on POSIX and Windows within one
file system), so an interruption or a concurrent reader never sees half a file, and an
existing file is only replaced by a complete new one.

**Temporary names** are short and recognisable whatever the destination's name:
``.mhtrack-<pid>-<random>.tmp<suffix>`` (:data:`TEMP_NAME`; at most 49 bytes, the suffix
kept only up to 16 bytes), so any output name the file system accepts (up to 255 bytes)
can be written, and readers that list folders skip them (:func:`is_temporary`).

**Failures name the file**: an ``OSError`` while writing (disk full, quota, permission,
I/O error) is raised again as :class:`OutputError` — still an ``OSError`` with its
``errno`` — whose message is one line naming the destination:
``out.csv: cannot write (No space left on device: the disk is full)``.

**Signals.** :func:`install_signal_cleanup` (called by the ``mhtrack`` command) makes
SIGTERM and SIGINT remove the temporaries of the writes in flight and the registered
temporary folders (:func:`temporary_dir`) before the process ends.

**SIGKILL** cannot be caught: its temporary stays, named with its writer's pid. The writer
holds an exclusive ``flock`` on its temporary for as long as it writes; the kernel drops
the lock when the process dies, however it dies. The first write of a process in a
folder removes the temporaries there whose writer is provably gone: nobody holds the
lock. We chose the lock over the pid (and its start time): a pid is reused, and a writer
on another machine sharing the folder has its own pids; the lock covers both. Only on a
file system without locks does the pid decide (gone when no process has it).
Temporaries of live writers are never touched.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import secrets
import shutil
import signal
import tempfile
from collections.abc import Iterator
from pathlib import Path
from types import FrameType
from typing import Any

from mhtrack.errors import printable

#: Name of a temporary: pid of its writer, random part, ``.tmp`` and the suffix.
TEMP_NAME = re.compile(r"\.mhtrack-(\d+)-([0-9a-f]{12})\.tmp(\.[^/]{0,16})?")
#: Longest destination suffix kept on a temporary (writers that choose a format by it).
MAX_SUFFIX = 16

_IN_FLIGHT: dict[str, int] = {}  # temporary path -> fd holding its lock
_TEMP_DIRS: dict[str, None] = {}
_CLEANED: set[str] = set()  # folders already swept by this process


class OutputError(OSError):
    """An output file could not be written; the message names it (an ``OSError``)."""

    def __str__(self) -> str:
        return str(self.strerror)


def output_error(path: str | os.PathLike[str], e: OSError) -> OutputError:
    """:class:`OutputError` naming ``path`` for the OS error ``e`` (disk full spelt out)."""
    what = e.strerror or str(e)
    if e.errno in (errno.ENOSPC, errno.EDQUOT):
        what += ": the disk is full" if e.errno == errno.ENOSPC else ": over quota"
    return OutputError(e.errno, f"{printable(path)}: cannot write ({what})", os.fspath(path))


def is_temporary(name: str | os.PathLike[str]) -> bool:
    """``name`` (a file name or path) is an atomic writer's temporary."""
    return TEMP_NAME.fullmatch(Path(name).name) is not None


def _temp_name(path: Path) -> str:
    suffix = path.suffix if len(os.fsencode(path.suffix)) <= MAX_SUFFIX else ""
    return f".mhtrack-{os.getpid()}-{secrets.token_hex(6)}.tmp{suffix}"


def _lock(fd: int) -> None:
    with contextlib.suppress(ImportError, OSError):
        import fcntl

        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True  # another user's process
    return True


def _stale(path: Path, pid: int) -> bool:
    """The writer of the temporary ``path`` is gone: nobody holds the temporary's lock
    (the kernel drops it with its process, however it ends; a pid alone proves nothing:
    it is reused, and a writer on another machine sharing the folder has a pid of its
    own). Where the file system has no locks, the pid decides: gone when no process has
    it."""
    try:
        import fcntl
    except ImportError:
        return False
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False  # a live writer holds it
    except OSError:
        return pid != os.getpid() and not _pid_alive(pid)
    finally:
        os.close(fd)
    return True


def remove_stale(folder: str | os.PathLike[str]) -> list[Path]:
    """Remove the temporaries in ``folder`` whose writer is gone (module docstring); the
    removed paths."""
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        m = TEMP_NAME.fullmatch(entry.name)
        if m is None or entry.path in _IN_FLIGHT:
            continue
        with contextlib.suppress(OSError):
            if entry.is_file(follow_symlinks=False) and _stale(Path(entry.path), int(m[1])):
                os.unlink(entry.path)
                removed.append(Path(entry.path))
    return removed


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str], *, make_parent: bool = True) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` for any writer (``np.savez``,
    ``pq.write_table``, ``Figure.savefig``, …); on success it is flushed to disk (fsync) and
    replaces ``path``, on an exception it is removed and ``path`` is left as it was. The
    parent folder is created (``make_parent``; else a missing one raises
    :class:`OutputError` with ``errno.ENOENT``). The temporary name keeps ``path``'s suffix (up to
    :data:`MAX_SUFFIX` bytes), for writers that choose a format by it. The new file gets the
    permissions an ordinary ``open(path, "w")`` would give (``0o666`` less the umask).
    An ``OSError`` becomes :class:`OutputError` naming ``path``."""
    path = Path(path)
    try:
        if make_parent:
            path.parent.mkdir(parents=True, exist_ok=True)
        folder = os.fspath(path.absolute().parent)
        if folder not in _CLEANED:
            _CLEANED.add(folder)
            remove_stale(folder)
        tmp = str(path.parent / _temp_name(path))
        fd = os.open(tmp, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o600)
    except OSError as e:
        raise output_error(path, e) from None
    _IN_FLIGHT[tmp] = fd
    try:
        _lock(fd)
        yield Path(tmp)
        _fsync(tmp)
        os.chmod(tmp, _default_mode())
        os.replace(tmp, path)
    except BaseException as e:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(e, OSError) and not isinstance(e, OutputError):
            raise output_error(path, e) from None
        raise
    finally:
        _IN_FLIGHT.pop(tmp, None)
        with contextlib.suppress(OSError):
            os.close(fd)


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
    """Write ``data`` (text as UTF-8) to ``path`` atomically (see :func:`atomic_path`).
    Text holding a file name that is not UTF-8 (surrogate escapes) gets its odd bytes
    as ``\\xNN`` (:func:`~mhtrack.errors.printable`): the file stays valid UTF-8."""
    if isinstance(data, str):
        try:
            data = data.encode("utf-8")
        except UnicodeEncodeError:
            data = printable(data).encode("utf-8")
    with atomic_path(path, make_parent=make_parent) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
    return Path(path)


@contextlib.contextmanager
def temporary_dir(prefix: str = "mhtrack-") -> Iterator[Path]:
    """A temporary folder (``tempfile.mkdtemp``) removed on leaving the block, and by the
    signal handler of :func:`install_signal_cleanup` if the process is stopped first."""
    d = tempfile.mkdtemp(prefix=prefix)
    _TEMP_DIRS[d] = None
    try:
        yield Path(d)
    finally:
        _TEMP_DIRS.pop(d, None)
        shutil.rmtree(d, ignore_errors=True)


def remove_in_flight() -> None:
    """Remove the temporaries of the writes in flight and the registered temporary
    folders (what the signal handler does)."""
    for tmp in list(_IN_FLIGHT):
        with contextlib.suppress(OSError):
            os.unlink(tmp)
    for d in list(_TEMP_DIRS):
        shutil.rmtree(d, ignore_errors=True)


def _on_signal(signum: int, frame: FrameType | None) -> Any:
    if os.getpid() != _INSTALLED_BY[0]:  # a forked child: the default action
        signal.signal(signum, signal.SIG_DFL)
        os.kill(os.getpid(), signum)
        return None
    remove_in_flight()
    previous = _PREVIOUS.get(signum)
    if callable(previous):
        return previous(signum, frame)
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise SystemExit(128 + signum)


_PREVIOUS: dict[int, Any] = {}
_INSTALLED_BY = [0]


def install_signal_cleanup() -> None:
    """Handle SIGTERM and SIGINT: remove the temporaries in flight (:func:`remove_in_flight`),
    then call the handler that was there (Python's for SIGINT: ``KeyboardInterrupt``), or
    end with status ``128 + signal`` (SIGTERM: 143). Only from the main thread; once. A
    forked child process takes the default action (it has no writes of its parent's)."""
    _INSTALLED_BY[0] = os.getpid()
    for signum in (signal.SIGTERM, signal.SIGINT):
        current = signal.getsignal(signum)
        if current is _on_signal:
            continue
        with contextlib.suppress(ValueError, OSError):  # not the main thread
            signal.signal(signum, _on_signal)
            _PREVIOUS[signum] = (current if callable(current)
                                 and current is not signal.default_int_handler else None)
