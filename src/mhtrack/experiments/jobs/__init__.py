"""The one job runner of every study (``montecarlo``, ``reproduce p1``, ``reproduce p2``).

A study is a list of :class:`Job` (generic key, plain-data parameters, parameter hash)
and a top-level job function. :func:`run_jobs` runs the jobs not yet done in a
:class:`JobStore` (one file per job, written atomically; resume skips a job whose stored
hash matches) on one executor — this process, local processes or Dask
(:func:`execute`) — and :func:`run_seed` gives every run its seed (:mod:`.seeds`).

* :mod:`~mhtrack.experiments.jobs.job` — :class:`Job`, :func:`params_hash`;
* :mod:`~mhtrack.experiments.jobs.plan` — :class:`JobPlan`, a lazy list of jobs;
* :mod:`~mhtrack.experiments.jobs.seeds` — :func:`run_seed`, :func:`run_seeds`;
* :mod:`~mhtrack.experiments.jobs.store` — :class:`JobStore`, :class:`JsonRecords`,
  :class:`ParquetRecords`;
* :mod:`~mhtrack.experiments.jobs.executor` — :func:`execute`, :func:`check_executor`;
* :mod:`~mhtrack.experiments.jobs.runner` — :func:`run_jobs`, :class:`JobsRun`;
* :mod:`~mhtrack.experiments.jobs.lifetime` — local workers that end with their parent.
"""

from mhtrack.experiments.jobs.executor import EXECUTORS, check_executor, execute
from mhtrack.experiments.jobs.job import COMPACT, SPACED, Job, params_hash
from mhtrack.experiments.jobs.plan import JobPlan
from mhtrack.experiments.jobs.runner import JobsRun, run_jobs
from mhtrack.experiments.jobs.seeds import run_seed, run_seeds
from mhtrack.experiments.jobs.store import JobStore, JsonRecords, ParquetRecords, RecordFormat

__all__ = [
    "COMPACT",
    "EXECUTORS",
    "SPACED",
    "Job",
    "JobPlan",
    "JobStore",
    "JobsRun",
    "JsonRecords",
    "ParquetRecords",
    "RecordFormat",
    "check_executor",
    "execute",
    "params_hash",
    "run_jobs",
    "run_seed",
    "run_seeds",
]
