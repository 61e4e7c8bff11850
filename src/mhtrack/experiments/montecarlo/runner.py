"""Run (or resume) a Monte-Carlo study into a directory."""

from __future__ import annotations

import json
import os
import re
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

from mhtrack.experiments.jobs import Job, JobStore, check_executor, run_jobs
from mhtrack.experiments.montecarlo.job import RECORDS, run_job
from mhtrack.experiments.montecarlo.result import MonteCarloResult, load_results, run_store
from mhtrack.experiments.montecarlo.spec import (
    SPEC_FILE,
    MonteCarloSpec,
    SpecMismatchError,
    check_study,
)
from mhtrack.io.atomic import atomic_write

#: A run's record file: ``run-<i>`` and the record suffix.
_RUN_FILE = re.compile(r"run-(0|[1-9][0-9]*)" + re.escape(RECORDS.suffix))


def run_montecarlo(
    spec: MonteCarloSpec,
    out_dir: str | os.PathLike[str],
    *,
    executor: str = "local",
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    job_function: Callable[[Mapping[str, Any]], Mapping[str, Any]] | None = None,
) -> MonteCarloResult:
    """Run (or resume) the study ``spec`` into ``out_dir`` and return its results.

    Parameters
    ----------
    executor : ``"local"`` — a :class:`~concurrent.futures.ProcessPoolExecutor` of
        ``workers`` processes (default ``os.cpu_count()``; ``1`` runs in this process, no
        pool) — or ``"dask"`` — a :class:`distributed.Client` on ``scheduler`` (an address
        such as ``"tcp://host:8786"``, or a ``Client`` / ``LocalCluster`` object).
    progress : a tqdm bar over jobs on stderr.
    job_function : top-level function run on each job instead of
        :func:`~mhtrack.experiments.montecarlo.job.run_job` (tests).

    Writes ``out_dir/montecarlo.json`` (the spec) and one file per job,
    ``runs/<tracker>/run-<i>.parquet``, or ``run-<i>.error.txt`` for a job that raised (the
    others go on). Jobs already done (same stored ``job_hash``) are skipped. Raises
    :class:`SpecMismatchError` if ``out_dir`` holds a study with other parameters, or a
    run file of other parameters. Writes no report (:mod:`mhtrack.reports.montecarlo`).
    """
    check_executor(executor, workers, scheduler)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    check_study(spec, out_dir)
    store = run_store(out_dir)
    for job in _stored_jobs(spec, store):
        h = store.stored_hash(job)
        if h is not None and h != job.hash:
            raise SpecMismatchError(
                f"{store.path(job.key)} holds a run of other parameters (job hash "
                f"{h[:12]}…, expected {job.hash[:12]}…); use another --out directory or "
                "delete it")
    atomic_write(out_dir / SPEC_FILE, json.dumps(spec.to_dict(), indent=1) + "\n")
    done = run_jobs(spec.plan(), job_function or run_job, store, executor=executor,
                    workers=workers, scheduler=scheduler, progress=progress,
                    desc="montecarlo", unit="run")
    result = load_results(out_dir)
    result.computed = done.computed
    result.skipped = done.skipped
    return result


def _stored_jobs(spec: MonteCarloSpec, store: JobStore) -> Iterator[Job]:
    """The jobs of ``spec`` that have a record file in ``store`` (found by listing the
    tracker folders, not by making every job of the study)."""
    for tracker in spec.trackers:
        folder = store.root / tracker
        if not folder.is_dir():
            continue
        found = (_RUN_FILE.fullmatch(entry.name) for entry in os.scandir(folder))
        for run in sorted(int(m.group(1)) for m in found if m is not None):
            if run < spec.runs:
                yield spec.job(tracker, run)
