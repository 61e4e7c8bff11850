"""Where jobs run: in this process, in a pool of local processes, or on a Dask cluster.

:func:`execute` runs ``fn(job.as_dict())`` for every job and calls ``finish(job, record,
error)`` in this process as each one ends (``error`` a traceback text, or ``None``).
Jobs are independent and each one's result depends on its parameters only, so the
records are the same whatever the executor, the number of workers or the order in which
jobs finish.
"""

from __future__ import annotations

import itertools
import os
import traceback
from collections.abc import Callable, Iterable, Iterator, Mapping
from typing import Any

from mhtrack.experiments.jobs.job import Job
from mhtrack.experiments.jobs.lifetime import end_with_parent, stop_pool

#: Executors: local processes (one worker: this process) or a Dask cluster.
EXECUTORS: tuple[str, ...] = ("local", "dask")

JobFunction = Callable[[Mapping[str, Any]], Mapping[str, Any]]
Finish = Callable[[Job, Mapping[str, Any] | None, str | None], None]

#: Jobs submitted ahead per worker: enough to keep every worker busy, few enough that a
#: study of 10⁶ runs holds a handful of jobs in memory.
IN_FLIGHT_PER_WORKER = 2


def check_executor(executor: str, workers: int | None, scheduler: Any) -> None:
    """Validate the executor arguments of :func:`execute` (``ValueError`` naming the bad one)."""
    if executor not in EXECUTORS:
        raise ValueError(f"executor: expected 'local' or 'dask', got {executor!r}")
    if executor == "dask" and scheduler is None:
        raise ValueError("executor 'dask' needs a scheduler address")
    if workers is not None and (isinstance(workers, bool) or workers < 1):
        raise ValueError(f"workers: expected an integer >= 1, got {workers!r}")


def execute(jobs: Iterable[Job], fn: JobFunction, finish: Finish, *, executor: str = "local",
            workers: int | None = None, scheduler: Any = None) -> None:
    """Run ``fn(job.as_dict())`` for every job and ``finish(job, record, error)`` as each
    ends: on a Dask cluster (``executor="dask"``, ``scheduler`` an address, a
    ``distributed.Client`` or a ``LocalCluster``), in this process (one worker, or one
    job), or in a pool of ``workers`` local processes (default: the CPU count).

    ``jobs`` is consumed lazily: at most :data:`IN_FLIGHT_PER_WORKER` jobs per worker are
    submitted ahead, so a study of any length holds a bounded number of jobs in memory.
    Local workers end with this process (:mod:`~mhtrack.experiments.jobs.lifetime`)."""
    check_executor(executor, workers, scheduler)
    it = iter(jobs)
    head = list(itertools.islice(it, 2))
    if not head:
        return
    jobs_it = itertools.chain(head, it)
    n_workers = workers or os.cpu_count() or 1
    if executor == "dask":
        _run_dask(jobs_it, fn, scheduler, finish, n_workers)
    elif n_workers == 1 or len(head) <= 1:
        for job in jobs_it:
            _run_inline(job, fn, finish)
    else:
        _run_pool(jobs_it, fn, n_workers, finish)


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


def _run_pool(jobs: Iterator[Job], fn: JobFunction, workers: int, finish: Finish) -> None:
    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait

    # "fork" where there is one: "spawn" would re-import the caller's __main__ module, which
    # breaks scripts without an ``if __name__ == "__main__"`` guard.
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                               initializer=end_with_parent, initargs=(os.getpid(),))
    running: dict[Future[Mapping[str, Any]], Job] = {}
    try:
        for job in itertools.chain(jobs, [None]):
            if job is not None:
                running[pool.submit(fn, job.as_dict())] = job
                if len(running) < IN_FLIGHT_PER_WORKER * workers:
                    continue
            while running:  # a slot is free again once one job ends; at the end, all
                done, _ = wait(running, return_when=FIRST_COMPLETED)
                for fut in done:
                    exc = fut.exception()
                    if exc is not None:
                        finish(running.pop(fut), None, _exc_text(exc))
                    else:
                        finish(running.pop(fut), fut.result(), None)
                if job is not None:
                    break
    except BaseException:  # e.g. Ctrl-C: stop the workers now; finished jobs are stored
        stop_pool(pool)
        raise
    pool.shutdown(wait=True)


#: The one line when Dask is missing (it is the optional extra ``dask``).
MISSING_DASK = ("--dask-scheduler needs Dask's distributed scheduler: "
                "pip install 'mhtrack[dask]'")


def require_dask() -> None:
    """Raise :class:`ImportError` with :data:`MISSING_DASK` when ``distributed`` is not
    installed."""
    try:
        import distributed  # noqa: F401
    except ImportError as e:
        raise ImportError(MISSING_DASK) from e


def dask_key(job: Job) -> str:
    """The Dask task key of ``job``: ``mhtrack-<key with / as ->-<hash[:12]>``."""
    return f"mhtrack-{job.key.replace('/', '-')}-{job.hash[:12]}"


def _run_dask(jobs: Iterator[Job], fn: JobFunction, scheduler: Any, finish: Finish,
              window: int) -> None:
    require_dask()
    from distributed import Client, as_completed

    own = not isinstance(scheduler, Client)
    if own:
        address = getattr(scheduler, "scheduler_address", scheduler)  # a LocalCluster
        client = Client(address)
    else:
        client = scheduler
    futures: dict[Any, Job] = {}

    def submit(job: Job) -> Any:
        fut = client.submit(fn, job.as_dict(), pure=False, key=dask_key(job))
        futures[fut] = job
        return fut

    try:
        n_ahead = IN_FLIGHT_PER_WORKER * max(window, _dask_threads(client))
        ahead = [submit(job) for job in itertools.islice(jobs, n_ahead)]
        done = as_completed(ahead)
        try:
            for fut in done:
                job = futures.pop(fut)
                if fut.status == "error":
                    exc = fut.exception()
                    tb = fut.traceback()
                    finish(job, None, "".join(traceback.format_exception(type(exc), exc, tb)))
                elif fut.status == "cancelled":
                    finish(job, None, "cancelled by the Dask cluster\n")
                else:
                    finish(job, fut.result(), None)
                fut.release()
                nxt = next(jobs, None)
                if nxt is not None:
                    done.add(submit(nxt))
        except BaseException:
            client.cancel(list(futures))
            raise
    finally:
        if own:
            client.close()


def _dask_threads(client: Any) -> int:
    """The cluster's worker threads (1 if it cannot say)."""
    try:
        return max(1, sum(client.nthreads().values()))
    except Exception:  # an old or unreachable scheduler: the window still bounds memory
        return 1
