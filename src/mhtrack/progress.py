"""The one progress bar of mhtrack: tqdm on stderr when enabled, nothing at all when not
(the CLI enables it on a terminal, or with ``--progress``; never with ``--quiet``:
:func:`mhtrack.cli.terminal.show_progress`).

* :class:`Stages` — over the named stages of one long computation (``evaluate``,
  ``report``); each stage is also logged at DEBUG on the ``mhtrack`` logger, with its
  duration;
* :class:`Count` — over units counted towards a total: frames (``track``, ``run``),
  bytes of a recording (``convert``), rows of a table (``export``), runs or jobs (the
  Monte-Carlo studies, ``cluster``, ``initiate``)."""

from __future__ import annotations

import logging
import sys
import time
from collections.abc import Callable, Iterable, Iterator
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


class Count:
    """A progress bar counting ``unit``\\ s (frames, bytes, rows, runs) towards ``total``
    (``None``: unknown) — tqdm on stderr when ``enabled``, else nothing at all (a
    disabled tqdm returns from every call at once). ``scale``: SI prefixes (bytes)."""

    def __init__(self, total: int | None, desc: str, unit: str, enabled: bool = False, *,
                 scale: bool = False) -> None:
        from tqdm.auto import tqdm

        self.position = 0
        self.bar = tqdm(total=total, desc=desc, unit=unit, unit_scale=scale,
                        disable=not enabled, file=sys.stderr, leave=False,
                        dynamic_ncols=True)

    def update(self, n: int = 1) -> None:
        """``n`` more units done."""
        self.position += n
        self.bar.update(n)

    def to(self, position: int) -> None:
        """Done up to ``position`` (e.g. the byte offset reached), never backwards."""
        if position > self.position:
            self.update(position - self.position)

    def note(self, text: str) -> None:
        """A short text after the bar (e.g. ``3 failed``)."""
        self.bar.set_postfix_str(text)

    def over(self, items: Iterable[T]) -> Iterator[T]:
        """``items``, one unit counted as each is done (when the next is asked for)."""
        for item in items:
            yield item
            self.update()

    def close(self) -> None:
        self.bar.close()

    def __enter__(self) -> Count:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def count(total: int | None = None, desc: str = "", unit: str = "it",
          enabled: bool = False, **kw: Any) -> Count:
    """A :class:`Count` (disabled unless ``enabled``: the library's default)."""
    return Count(total, desc, unit, enabled, **kw)
