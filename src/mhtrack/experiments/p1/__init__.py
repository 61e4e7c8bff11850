"""Reproduce P1 §3: the Monte-Carlo study of ``crossing`` and P1's Table 3 and Figs. 2–6.
Run it with ``mhtrack reproduce p1``, or :func:`reproduce_p1` then
:func:`mhtrack.reports.p1.write_p1_report`.

* :mod:`~mhtrack.experiments.p1.constants` — trackers, P1's Table 3, our columns, the
  study's keywords, file names;
* :mod:`~mhtrack.experiments.p1.study` — :func:`reproduce_p1` (the Monte-Carlo study
  into ``DIR/montecarlo/``, Table 3's numbers, run 0 recomputed) and
  :class:`P1Reproduction`.
"""

from mhtrack.experiments.p1.study import P1Reproduction, reproduce_p1

__all__ = ["P1Reproduction", "reproduce_p1"]
