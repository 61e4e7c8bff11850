"""Worker processes that end with their parent, and a pool stopped at once on Ctrl-C.

A local worker runs :func:`end_with_parent` first (the pool's ``initializer``):

* it ignores ``SIGINT``: Ctrl-C in a terminal reaches the whole process group, and only
  the parent acts on it (it stops the pool, :func:`stop_pool`, and says how to resume),
  so no job is recorded as failed by a ``KeyboardInterrupt``;
* on Linux it asks the kernel for ``SIGKILL`` when its parent dies
  (``prctl(PR_SET_PDEATHSIG)``, prctl(2)); everywhere, a daemon thread checks
  ``os.getppid()`` every :data:`PARENT_POLL_S` seconds and exits when the parent has
  gone (the worker was re-parented). A parent killed with ``SIGKILL`` runs no clean-up of
  its own, so these are what keep its workers from running on as orphans.

Workers write nothing: records are stored by the parent as jobs end, so killing a worker
loses at most the job it was running.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time
from typing import Any

#: How often (s) a worker checks that its parent is alive, where prctl is not available.
PARENT_POLL_S = 0.5
#: ``PR_SET_PDEATHSIG`` of ``<linux/prctl.h>``.
_PR_SET_PDEATHSIG = 1


def _set_parent_death_signal() -> None:
    """``prctl(PR_SET_PDEATHSIG, SIGKILL)`` on Linux; nothing elsewhere or on failure."""
    if not sys.platform.startswith("linux"):
        return
    import ctypes

    with contextlib.suppress(OSError, AttributeError):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)


def _watch_parent(parent_pid: int) -> None:
    while True:
        if os.getppid() != parent_pid:
            os._exit(1)
        time.sleep(PARENT_POLL_S)


def end_with_parent(parent_pid: int) -> None:
    """Make this (worker) process end when process ``parent_pid`` ends (module docstring)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _set_parent_death_signal()
    if os.getppid() != parent_pid:  # the parent died before prctl took effect
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent_pid,), daemon=True,
                     name="mhtrack-parent-watch").start()


def stop_pool(pool: Any) -> None:
    """Stop a :class:`~concurrent.futures.ProcessPoolExecutor` now: cancel the queued
    jobs and terminate the workers (their running jobs are lost, finished ones are
    already stored)."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in processes:
        with contextlib.suppress(Exception):
            p.terminate()
    for p in processes:
        with contextlib.suppress(Exception):
            p.join(5)
            if p.is_alive():
                p.kill()
