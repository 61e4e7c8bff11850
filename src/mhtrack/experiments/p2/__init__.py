"""Reproduce P2 (Gong, Dai & Ma 2013, multi-radar track initiation: adaptive K-means
fusion of the radars' plots, then modified 3/4 logic or modified Hough initiation): the θ
sweeps of Figs. 3–4, Figs. 2 and 12–15, Tables 1–2, on the ``multiradar`` preset
(``docs/initiation.md``). Run it with ``mhtrack reproduce p2`` or :func:`reproduce_p2`.

One concept per module:

* :mod:`~mhtrack.experiments.p2.constants` — grids, nominal setting, P2's printed numbers,
  labels, output file names;
* :mod:`~mhtrack.experiments.p2.jobs` — scenario, run seeds, the ``grid`` /
  ``clustering`` / ``methods`` job functions, :func:`make_jobs`, and :func:`run_jobs`
  (local processes or Dask, resuming from ``DIR/jobs/``);
* :mod:`~mhtrack.experiments.p2.aggregate` — the jobs' counts summed into curves and
  tables;
* :mod:`~mhtrack.experiments.p2.figures` — Figs. 2, 3–4 and 12–15;
* :mod:`~mhtrack.experiments.p2.report` — ``tables.md`` and ``report.md``;
* :mod:`~mhtrack.experiments.p2.study` — the entry point :func:`reproduce_p2` and
  :class:`P2Reproduction`.

:mod:`mhtrack.experiments.reproduce_p2` re-exports every name of the module it was before
this split.
"""

from mhtrack.experiments.p2.study import P2Reproduction, reproduce_p2

__all__ = ["P2Reproduction", "reproduce_p2"]
