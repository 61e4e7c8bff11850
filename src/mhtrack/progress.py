"""A progress bar over the named stages of one long computation (``evaluate``, ``report``):
tqdm on stderr when enabled, nothing at all when not (the CLI enables it only on a
terminal, :func:`mhtrack.cli.terminal.progress_enabled`). Each stage is also logged at
DEBUG on the ``mhtrack`` logger, with its duration."""

from __future__ import annotations

import logging
import sys
import time
from collections.abc import Callable
from typing import Any, TypeVar

T = TypeVar("T")
log = logging.getLogger("mhtrack.progress")


class Stages:
    """``stages(name, fn, *args)`` runs ``fn(*args)`` as the stage ``name`` (the bar shows
    it, then advances); ``close()`` ends the bar. ``total`` is the number of stages."""

    def __init__(self, total: int, desc: str, enabled: bool = False) -> None:
        from tqdm.auto import tqdm

        self.desc = desc
        self.bar = tqdm(total=total, desc=desc, unit="step", disable=not enabled,
                        file=sys.stderr, leave=False, dynamic_ncols=True)

    def __call__(self, name: str, fn: Callable[..., T], *args: Any, **kw: Any) -> T:
        self.bar.set_postfix_str(name, refresh=True)
        t0 = time.perf_counter()
        out = fn(*args, **kw)
        log.debug("%s: %s in %.3f s", self.desc, name, time.perf_counter() - t0)
        self.bar.update()
        return out

    def close(self) -> None:
        self.bar.close()


#: Stages that do nothing but run (the default of a library call: no bar, no output).
def silent(desc: str = "") -> Stages:
    """A :class:`Stages` with its bar disabled."""
    return Stages(0, desc, enabled=False)
