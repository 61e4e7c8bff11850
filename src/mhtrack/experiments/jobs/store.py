"""The job store: one file per finished job, written atomically, and resume.

``JobStore(root, fmt)`` keeps job ``key``'s record in ``root/<key><fmt.suffix>`` and a
failed job's traceback in ``root/<key>.error.txt``. Every file is written with
:func:`mhtrack.io.atomic.atomic_write` / :func:`~mhtrack.io.atomic.atomic_path`, so an
interruption never leaves half a record. Each record file holds its job's hash; a job is
*done* when its file exists, can be read and holds the job's hash — resume skips exactly
those, and recomputes a missing, partial or corrupted file.

Two record formats: :class:`JsonRecords` (``{"job": params + job_hash, "result":
record}``) and :class:`ParquetRecords` (a one-row Parquet table, the hash in the schema
metadata ``mhtrack.job_hash``).
"""

from __future__ import annotations

import contextlib
import json
import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from mhtrack.errors import InputError
from mhtrack.experiments.jobs.job import Job
from mhtrack.io.atomic import atomic_path, atomic_write
from mhtrack.io.paths import arrow_file

#: Checks a done job's record (raises ``ValueError("<field>: <problem>")``).
RecordCheck = Callable[[Job, Mapping[str, Any]], None]

ERROR_SUFFIX = ".error.txt"


class RecordFormat(ABC):
    """How a job's record is written to and read from one file."""

    #: File name suffix, e.g. ``".json"``.
    suffix: str

    @abstractmethod
    def write(self, path: Path, job: Job, record: Mapping[str, Any]) -> None:
        """Write ``record`` of ``job`` to ``path`` atomically."""

    @abstractmethod
    def read(self, path: Path) -> dict[str, Any]:
        """The record stored in ``path``."""

    @abstractmethod
    def stored_hash(self, path: Path) -> str | None:
        """The job hash stored in ``path``; ``None`` if it cannot be read."""


class JsonRecords(RecordFormat):
    """``{"job": {…params, "job_hash"}, "result": record}`` as one line of JSON."""

    suffix = ".json"

    def write(self, path: Path, job: Job, record: Mapping[str, Any]) -> None:
        atomic_write(path, json.dumps({"job": job.as_dict(), "result": record}) + "\n")

    def _load(self, path: Path) -> dict[str, Any] | None:
        try:
            d = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None
        return d if isinstance(d, dict) else None

    def read(self, path: Path) -> dict[str, Any]:
        d = self._load(path)
        if d is None or "result" not in d:
            raise InputError(f"{path}: not a job record (expected a JSON object with 'job' "
                             "and 'result')", file=str(path))
        return d["result"]

    def stored_hash(self, path: Path) -> str | None:
        d = self._load(path)
        if d is None or not isinstance(d.get("job"), dict) or "result" not in d:
            return None
        h = d["job"].get("job_hash")
        return h if isinstance(h, str) else None


class ParquetRecords(RecordFormat):
    """A one-row Parquet table: ``bool``, ``int64``, ``string`` or ``float64`` scalars
    (``None`` as a null ``float64``), lists as ``list<int64>`` for the columns in
    ``int_lists`` and ``list<float64>`` otherwise. Reading gives nulls back as NaN except
    in the ``keep_none`` columns."""

    suffix = ".parquet"

    def __init__(self, int_lists: frozenset[str] = frozenset(),
                 keep_none: frozenset[str] = frozenset()) -> None:
        self.int_lists = frozenset(int_lists)
        self.keep_none = frozenset(keep_none)

    def _type(self, key: str, v: Any) -> Any:
        import pyarrow as pa

        if isinstance(v, list):
            return pa.list_(pa.int64() if key in self.int_lists else pa.float64())
        if isinstance(v, bool):
            return pa.bool_()
        if isinstance(v, int):
            return pa.int64()
        if isinstance(v, str):
            return pa.string()
        return pa.float64()  # floats, and None (a metric that was NaN)

    def write(self, path: Path, job: Job, record: Mapping[str, Any]) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        fields, arrays = [], []
        for k, v in record.items():
            t = self._type(k, v)
            fields.append(pa.field(k, t))
            arrays.append(pa.array([v], type=t))
        meta = {b"mhtrack.job_hash": job.hash.encode()}
        table = pa.Table.from_arrays(arrays, schema=pa.schema(fields, metadata=meta))
        with atomic_path(path) as tmp, arrow_file(tmp, "wb") as fh:
            pq.write_table(table, fh)

    def read(self, path: Path) -> dict[str, Any]:
        import pyarrow as pa
        import pyarrow.parquet as pq

        try:
            with arrow_file(path) as fh:
                rows = pq.read_table(fh).to_pylist()
        except (OSError, pa.ArrowException) as e:
            raise InputError(f"{path}: not a readable job record ({str(e)[:120]})",
                             file=str(path)) from None
        if len(rows) != 1:
            raise InputError(f"{path}: a job record holds one row, this one {len(rows)}",
                             file=str(path))
        return {k: (math.nan if v is None and k not in self.keep_none else v)
                for k, v in rows[0].items()}

    def stored_hash(self, path: Path) -> str | None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        try:
            with arrow_file(path) as fh:
                meta = pq.read_schema(fh).metadata or {}
        except (OSError, pa.ArrowException):
            return None
        h = meta.get(b"mhtrack.job_hash")
        return h.decode() if h is not None else None


class JobStore:
    """Job records under ``root``, one file per job (module docstring)."""

    def __init__(self, root: str | Path, fmt: RecordFormat,
                 check: RecordCheck | None = None) -> None:
        self.root = Path(root)
        self.fmt = fmt
        self.check = check

    def path(self, key: str) -> Path:
        """The record file of job ``key``."""
        return self.root / f"{key}{self.fmt.suffix}"

    def error_path(self, key: str) -> Path:
        """The traceback file of job ``key`` when it failed."""
        return self.root / f"{key}{ERROR_SUFFIX}"

    def stored_hash(self, job: Job) -> str | None:
        """The hash in ``job``'s record file; ``None`` if it is missing or unreadable."""
        p = self.path(job.key)
        return self.fmt.stored_hash(p) if p.is_file() else None

    def is_done(self, job: Job) -> bool:
        """``job``'s record file exists and holds ``job``'s hash."""
        return self.stored_hash(job) == job.hash

    def load(self, job: Job) -> dict[str, Any]:
        """The stored record of a done job, checked by the store's ``check`` (a record of
        the wrong shape is an :class:`~mhtrack.errors.InputError` naming the file and
        the field: ``jobs/grid-….json, key 'result.found': expected …``)."""
        path = self.path(job.key)
        record = self.fmt.read(path)
        if not isinstance(record, dict):
            raise InputError(f"{path}, key 'result': expected an object, got "
                             f"{type(record).__name__}", file=str(path), key="result")
        if self.check is not None:
            try:
                self.check(job, record)
            except (ValueError, TypeError, KeyError) as e:
                msg = str(e)
                field, _, problem = msg.partition(": ")
                key = f"result.{field}" if problem else "result"
                raise InputError(f"{path}, key {key!r}: {problem or msg}", file=str(path),
                                 key=key) from None
        return record

    def error(self, job: Job) -> str | None:
        """The stored traceback of ``job``, if it failed (and has not succeeded since)."""
        p = self.error_path(job.key)
        return p.read_text() if p.is_file() else None

    def save(self, job: Job, record: Mapping[str, Any]) -> None:
        """Store ``job``'s record (atomically) and drop an old error file."""
        self.fmt.write(self.path(job.key), job, record)
        with contextlib.suppress(FileNotFoundError):
            self.error_path(job.key).unlink()

    def save_error(self, job: Job, text: str) -> None:
        """Store ``job``'s traceback (atomically)."""
        atomic_write(self.error_path(job.key), text)
