"""Monte-Carlo studies: many simulated runs of several trackers, on local processes or Dask.

A study (:class:`MonteCarloSpec`) is a scenario, a list of trackers, a number of runs and a
base seed, plus the tracker configuration and keywords forwarded verbatim to
:func:`~mhtrack.experiments.pipeline.run_scenario`. It is cut into one job per
``(tracker, run)``, run by the job runner :mod:`mhtrack.experiments.jobs`:

* **Seeding** — run ``i`` simulates with ``run_seed(seed, i)`` (stream ``"spawn"``:
  child ``i`` of ``SeedSequence(seed)``, 63 bits). Every tracker sees the same plots in
  run ``i``, and no result depends on the number of workers, the executor or the order in
  which jobs finish.
* **Files** — ``DIR/montecarlo.json`` holds the full spec (written first); each finished
  job is written at once, atomically, to ``DIR/runs/<tracker>/run-<i>.parquet``: one row
  with every scalar of :meth:`~mhtrack.experiments.pipeline.ScenarioRun.summary` plus
  ``run``, ``seed``, ``base_seed``, ``scenario``, ``job_hash``, ``caps`` (JSON text), and
  the per-scan lists ``scans``, ``ospa``, ``gospa``, ``cardinality``,
  ``cardinality_true``. A job that raises leaves ``run-<i>.error.txt`` (its traceback)
  instead; the others go on.
* **Resume** — a rerun skips every job whose Parquet file holds the job's ``job_hash``
  (SHA-256 of its parameters). A directory whose ``montecarlo.json`` has another
  scenario, seed, config or run keywords is refused with :class:`SpecMismatchError`;
  ``trackers`` and ``runs`` may change (run ``i`` is the same job whatever the number of
  runs).
* **Summary** — :meth:`MonteCarloResult.summary`; the Markdown summary and the figure are
  written by :mod:`mhtrack.reports.montecarlo`.

Modules: :mod:`.spec` (the study, its jobs), :mod:`.job` (one job), :mod:`.result`
(records and summary), :mod:`.runner` (:func:`run_montecarlo`).
"""

from mhtrack.experiments.montecarlo.job import run_job
from mhtrack.experiments.montecarlo.result import MonteCarloResult, load_results
from mhtrack.experiments.montecarlo.runner import run_montecarlo
from mhtrack.experiments.montecarlo.spec import MonteCarloSpec, SpecMismatchError

__all__ = [
    "MonteCarloResult",
    "MonteCarloSpec",
    "SpecMismatchError",
    "load_results",
    "run_job",
    "run_montecarlo",
]
