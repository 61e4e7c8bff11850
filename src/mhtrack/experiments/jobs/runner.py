"""Run (or resume) a study's jobs into a :class:`~mhtrack.experiments.jobs.store.JobStore`."""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from mhtrack.experiments.jobs.executor import JobFunction, check_executor, execute
from mhtrack.experiments.jobs.job import Job
from mhtrack.experiments.jobs.plan import JobPlan
from mhtrack.experiments.jobs.store import JobStore
from mhtrack.progress import Count


@dataclass
class JobsRun:
    """What :func:`run_jobs` did: jobs ``computed`` now (failed ones included), jobs
    ``skipped`` as already done, and the traceback of each job that failed now."""

    computed: int
    skipped: int
    errors: dict[str, str] = field(default_factory=dict)


def run_jobs(jobs: Sequence[Job] | JobPlan, fn: JobFunction, store: JobStore, *,
             executor: str = "local", workers: int | None = None, scheduler: Any = None,
             progress: bool = False, desc: str = "jobs", unit: str = "job") -> JobsRun:
    """Run every job of ``jobs`` not done in ``store`` (:meth:`JobStore.is_done`) with
    :func:`~mhtrack.experiments.jobs.executor.execute`, storing each record — or its
    traceback — as the job ends. ``progress``: a bar of the jobs done
    (:class:`~mhtrack.progress.Count`). A job that raises does not stop the others; an
    interruption loses no finished job.

    ``jobs`` is a list (its keys are checked to be unique) or a lazy
    :class:`~mhtrack.experiments.jobs.plan.JobPlan` (unique by construction): jobs are
    made, checked against the store and handed to the executor one at a time, so the
    memory used does not grow with the number of jobs."""
    check_executor(executor, workers, scheduler)
    if not isinstance(jobs, JobPlan):
        keys = [j.key for j in jobs]
        if len(set(keys)) != len(keys):
            raise ValueError("run_jobs: two jobs share a key")
    out = JobsRun(computed=0, skipped=0)
    bar = Count(len(jobs), desc, unit, progress)

    def pending() -> Iterator[Job]:
        for job in jobs:
            if store.is_done(job):
                out.skipped += 1
                bar.update(1)
            else:
                out.computed += 1
                yield job

    def finish(job: Job, record: Mapping[str, Any] | None, error: str | None) -> None:
        if error is not None:
            store.save_error(job, error)
            out.errors[job.key] = error
            bar.note(f"{len(out.errors)} failed")
        else:
            assert record is not None
            store.save(job, record)
        bar.update(1)

    try:
        execute(pending(), fn, finish, executor=executor, workers=workers, scheduler=scheduler)
    finally:
        bar.close()
    return out
