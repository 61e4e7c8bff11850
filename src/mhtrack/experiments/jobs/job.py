"""A job: one unit of a study, named by a generic key and identified by the hash of its
parameters.

A study cuts its work into jobs of plain JSON data (``params``), each run by a top-level
job function ``fn(job.as_dict())`` — picklable, so it runs in this process, in a local
process pool or on a Dask cluster alike. ``key`` names the job within its study and its
files in the :class:`~mhtrack.experiments.jobs.store.JobStore` (``"mht/run-3"``,
``"grid-s20-l50-r0-2"``); ``hash`` is the SHA-256 of the parameters, what resume compares.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

#: Separators of the canonical JSON a hash is taken over: compact (``montecarlo``) or
#: ``json.dumps``' default (``reproduce p2``). Each study keeps the one its stored
#: directories were written with, so they resume without recomputing.
COMPACT: tuple[str, str] = (",", ":")
SPACED: tuple[str, str] = (", ", ": ")


def params_hash(params: Mapping[str, Any], separators: tuple[str, str] = COMPACT) -> str:
    """SHA-256 (hex) of ``json.dumps(params, sort_keys=True, separators=separators)``."""
    text = json.dumps(params, sort_keys=True, separators=separators)
    return hashlib.sha256(text.encode()).hexdigest()


@dataclass(frozen=True)
class Job:
    """One job: ``key`` (unique in its study, ``/``-separated like a relative path),
    ``params`` (plain JSON data) and ``hash`` (:func:`params_hash` of ``params``)."""

    key: str
    params: Mapping[str, Any]
    hash: str

    @classmethod
    def of(cls, key: str, params: Mapping[str, Any],
           separators: tuple[str, str] = COMPACT) -> Job:
        """The job ``key`` with ``params``, hashed with ``separators``."""
        return cls(key, dict(params), params_hash(params, separators))

    def as_dict(self) -> dict[str, Any]:
        """What the job function receives: the parameters plus ``job_hash``."""
        return {**self.params, "job_hash": self.hash}
