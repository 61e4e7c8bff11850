"""Reproduce P2 (Gong, Dai & Ma 2013, multi-radar track initiation: adaptive K-means
fusion of the radars' plots, then modified 3/4 logic or modified Hough initiation): the θ
sweeps of Figs. 3–4, Figs. 2 and 12–15, Tables 1–2, on the ``multiradar`` preset
(``docs/initiation.md``). Run it with ``mhtrack reproduce p2``, or
:func:`reproduce_p2` then :func:`mhtrack.reports.p2.write_p2_report`.

One concept per module:

* :mod:`~mhtrack.experiments.p2.constants` — grids, nominal setting, P2's printed numbers,
  labels, output file names;
* :mod:`~mhtrack.experiments.p2.jobs` — scenario, the ``grid`` / ``clustering`` /
  ``methods`` job functions and :func:`~mhtrack.experiments.p2.jobs.make_jobs` (run by
  :func:`mhtrack.experiments.jobs.run_jobs`, resuming from ``DIR/jobs/``);
* :mod:`~mhtrack.experiments.p2.aggregate` — the jobs' counts summed into curves and
  tables;
* :mod:`~mhtrack.experiments.p2.examples` — the single runs of Figs. 2 and 12–15;
* :mod:`~mhtrack.experiments.p2.study` — the entry point :func:`reproduce_p2` and
  :class:`P2Reproduction`.

The text and figures are written by :mod:`mhtrack.reports.p2`.
"""

from mhtrack.experiments.p2.study import P2Reproduction, reproduce_p2

__all__ = ["P2Reproduction", "reproduce_p2"]
