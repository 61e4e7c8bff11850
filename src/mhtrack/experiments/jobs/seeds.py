"""The one seeding scheme of every study: the seed of run ``r`` of a study with base seed
``seed`` is drawn from ``numpy.random.SeedSequence(seed)`` and depends on ``(seed, r)``
only — not on the number of runs, the workers, the executor or the order jobs finish in.

Two streams of that sequence are in use, each kept because stored study directories and
published numbers were made with it (changing one would change every result):

* ``"spawn"`` (``montecarlo``, ``reproduce p1``): child ``r`` of ``SeedSequence(seed)``
  (``SeedSequence(seed, spawn_key=(r,))``, the ``r``-th of ``SeedSequence(seed).spawn(n)``
  for any ``n > r``), its first 64-bit word shifted right by one (a 63-bit integer);
* ``"words"`` (``cluster``, ``initiate``, ``reproduce p2``): word ``r`` of
  ``SeedSequence(seed).generate_state(n, uint32)`` for any ``n > r`` (a 32-bit integer;
  the words are prefix-stable, so run ``r``'s seed is the same for any number of runs).

Every run of a study gets one seed, shared by everything compared on that run (every
tracker, every θ, every initiator), so the comparisons are paired.
"""

from __future__ import annotations

from typing import Literal

import numpy as np

Stream = Literal["spawn", "words"]
STREAMS: tuple[str, ...] = ("spawn", "words")


def _check(seed: int, runs: int) -> None:
    if runs < 1:
        raise ValueError(f"runs must be >= 1, got {runs}")
    if seed < 0:
        raise ValueError(f"seed must be >= 0, got {seed}")


def run_seeds(seed: int, runs: int, stream: Stream) -> list[int]:
    """The seeds of runs ``0 … runs − 1`` of a study with base seed ``seed`` (module
    docstring for the two streams)."""
    _check(int(seed), int(runs))
    if stream == "words":
        return [int(s) for s in np.random.SeedSequence(int(seed)).generate_state(
            int(runs), np.uint32)]
    if stream == "spawn":
        return [int(np.random.SeedSequence(int(seed), spawn_key=(r,)).generate_state(
            1, np.uint64)[0] >> np.uint64(1)) for r in range(int(runs))]
    raise ValueError(f"unknown seed stream {stream!r} (expected one of {', '.join(STREAMS)})")


def run_seed(seed: int, run: int, stream: Stream) -> int:
    """The seed of run ``run`` of a study with base seed ``seed``: ``run_seeds(seed, run +
    1, stream)[run]``, the same for any number of runs."""
    if stream == "spawn":
        _check(int(seed), int(run) + 1)
        ss = np.random.SeedSequence(int(seed), spawn_key=(int(run),))
        return int(ss.generate_state(1, np.uint64)[0] >> np.uint64(1))
    return run_seeds(seed, int(run) + 1, stream)[int(run)]
