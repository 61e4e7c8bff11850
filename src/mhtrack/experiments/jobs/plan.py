"""A lazy list of jobs: a study of 10⁶ runs holds one job at a time, not 10⁶.

:class:`JobPlan` has a length and makes job ``i`` when it is asked for it
(``make(i)``), so building the plan of a large study costs no memory and the first job
starts at once. A study whose jobs are a grid (run × tracker) gives its plan a ``make``
that computes job ``i`` from ``i`` alone; its keys are then unique by construction, which
:func:`~mhtrack.experiments.jobs.runner.run_jobs` trusts instead of collecting them.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass

from mhtrack.experiments.jobs.job import Job


@dataclass(frozen=True)
class JobPlan:
    """``length`` jobs, job ``i`` being ``make(i)`` (``0 ≤ i < length``), made on demand.
    ``make`` must give every ``i`` its own key."""

    length: int
    make: Callable[[int], Job]

    def __post_init__(self) -> None:
        if isinstance(self.length, bool) or not isinstance(self.length, int) or self.length < 0:
            raise ValueError(f"JobPlan: length must be an integer >= 0, got {self.length!r}")

    def __len__(self) -> int:
        return self.length

    def __iter__(self) -> Iterator[Job]:
        for i in range(self.length):
            yield self.make(i)

    def __getitem__(self, i: int) -> Job:
        if not -self.length <= i < self.length:
            raise IndexError(f"job {i} of a plan of {self.length}")
        return self.make(i % self.length)
