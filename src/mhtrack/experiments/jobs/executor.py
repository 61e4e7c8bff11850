"""Where jobs run: in this process, in a pool of local processes, or on a Dask cluster.

:func:`execute` runs ``fn(job.as_dict())`` for every job and calls ``finish(job, record,
error)`` in this process as each one ends (``error`` a traceback text, or ``None``).
Jobs are independent and each one's result depends on its parameters only, so the
records are the same whatever the executor, the number of workers or the order in which
jobs finish.
"""

from __future__ import annotations

import os
import traceback
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from mhtrack.experiments.jobs.job import Job

#: Executors: local processes (one worker: this process) or a Dask cluster.
EXECUTORS: tuple[str, ...] = ("local", "dask")

JobFunction = Callable[[Mapping[str, Any]], Mapping[str, Any]]
Finish = Callable[[Job, Mapping[str, Any] | None, str | None], None]


def check_executor(executor: str, workers: int | None, scheduler: Any) -> None:
    """Validate the executor arguments of :func:`execute` (``ValueError`` naming the bad one)."""
    if executor not in EXECUTORS:
        raise ValueError(f"executor: expected 'local' or 'dask', got {executor!r}")
    if executor == "dask" and scheduler is None:
        raise ValueError("executor 'dask' needs a scheduler address")
    if workers is not None and (isinstance(workers, bool) or workers < 1):
        raise ValueError(f"workers: expected an integer >= 1, got {workers!r}")


def execute(jobs: Sequence[Job], fn: JobFunction, finish: Finish, *, executor: str = "local",
            workers: int | None = None, scheduler: Any = None) -> None:
    """Run ``fn(job.as_dict())`` for every job and ``finish(job, record, error)`` as each
    ends: on a Dask cluster (``executor="dask"``, ``scheduler`` an address, a
    ``distributed.Client`` or a ``LocalCluster``), in this process (one worker, or one
    job), or in a pool of ``workers`` local processes (default: the CPU count)."""
    check_executor(executor, workers, scheduler)
    if not jobs:
        return
    n_workers = workers or os.cpu_count() or 1
    if executor == "dask":
        _run_dask(jobs, fn, scheduler, finish)
    elif n_workers == 1 or len(jobs) <= 1:
        for job in jobs:
            _run_inline(job, fn, finish)
    else:
        _run_pool(jobs, fn, n_workers, finish)


def _run_inline(job: Job, fn: JobFunction, finish: Finish) -> None:
    try:
        record = fn(job.as_dict())
    except Exception:
        finish(job, None, traceback.format_exc())
        return
    finish(job, record, None)


def _exc_text(exc: BaseException) -> str:
    text = "".join(traceback.format_exception(exc))
    cause = exc.__cause__  # ProcessPoolExecutor attaches the worker's traceback here
    return text if cause is None else text + "\n" + str(cause)


def _run_pool(jobs: Sequence[Job], fn: JobFunction, workers: int, finish: Finish) -> None:
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    # "fork" where there is one: "spawn" would re-import the caller's __main__ module, which
    # breaks scripts without an ``if __name__ == "__main__"`` guard.
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    with ProcessPoolExecutor(max_workers=min(workers, len(jobs)), mp_context=ctx) as pool:
        futures = {pool.submit(fn, job.as_dict()): job for job in jobs}
        try:
            for fut in as_completed(futures):
                exc = fut.exception()
                if exc is not None:
                    finish(futures[fut], None, _exc_text(exc))
                else:
                    finish(futures[fut], fut.result(), None)
        except BaseException:  # e.g. Ctrl-C: drop queued jobs; finished ones are stored
            pool.shutdown(wait=False, cancel_futures=True)
            raise


def dask_key(job: Job) -> str:
    """The Dask task key of ``job``: ``mhtrack-<key with / as ->-<hash[:12]>``."""
    return f"mhtrack-{job.key.replace('/', '-')}-{job.hash[:12]}"


def _run_dask(jobs: Sequence[Job], fn: JobFunction, scheduler: Any, finish: Finish) -> None:
    from distributed import Client, as_completed

    own = not isinstance(scheduler, Client)
    if own:
        address = getattr(scheduler, "scheduler_address", scheduler)  # a LocalCluster
        client = Client(address)
    else:
        client = scheduler
    try:
        futures = {client.submit(fn, job.as_dict(), pure=False, key=dask_key(job)): job
                   for job in jobs}
        try:
            for fut in as_completed(list(futures)):
                job = futures[fut]
                if fut.status == "error":
                    exc = fut.exception()
                    tb = fut.traceback()
                    finish(job, None, "".join(traceback.format_exception(type(exc), exc, tb)))
                elif fut.status == "cancelled":
                    finish(job, None, "cancelled by the Dask cluster\n")
                else:
                    finish(job, fut.result(), None)
                fut.release()
        except BaseException:
            client.cancel(list(futures))
            raise
    finally:
        if own:
            client.close()
