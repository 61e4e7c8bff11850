"""Lazy job plans: a study of 10⁶ runs holds a bounded number of jobs in memory."""

import tracemalloc

import pytest

from mhtrack.experiments.jobs import Job, JobPlan, JobStore, JsonRecords, run_jobs
from mhtrack.experiments.jobs.executor import IN_FLIGHT_PER_WORKER
from mhtrack.experiments.montecarlo import MonteCarloSpec, run_montecarlo
from mhtrack.experiments.montecarlo.spec import MAX_RUNS
from mhtrack.scenario import preset


def double(job):
    return {"y": 2 * job["x"]}


def make(i):
    return Job.of(f"x-{i}", {"x": i})


class Stop(BaseException):
    """Stands in for Ctrl-C (a BaseException, so the runner lets it through)."""


def test_a_plan_is_a_lazy_sequence():
    plan = JobPlan(5, make)
    assert len(plan) == 5
    assert [j.key for j in plan] == [f"x-{i}" for i in range(5)]
    assert plan[-1] == make(4)
    with pytest.raises(IndexError):
        plan[5]
    with pytest.raises(ValueError):
        JobPlan(-1, make)


def test_a_plan_and_a_list_store_the_same_records(tmp_path):
    a, b = JobStore(tmp_path / "a", JsonRecords()), JobStore(tmp_path / "b", JsonRecords())
    ra = run_jobs([make(i) for i in range(6)], double, a, workers=1)
    rb = run_jobs(JobPlan(6, make), double, b, workers=2)
    assert (ra.computed, ra.skipped) == (rb.computed, rb.skipped) == (6, 0)
    for i in range(6):
        assert a.path(f"x-{i}").read_bytes() == b.path(f"x-{i}").read_bytes()
    again = run_jobs(JobPlan(8, make), double, b, workers=1)
    assert (again.computed, again.skipped) == (2, 6)


def test_montecarlo_of_a_million_runs_starts_in_little_memory(tmp_path):
    """The plan of 10⁶ runs × 3 trackers is made job by job: the memory allocated up to
    the first job is that of a few jobs (a list of the 3·10⁶ jobs took 2.7 GB)."""
    spec = MonteCarloSpec(preset("crossing"), runs=MAX_RUNS, seed=1)
    seen = []

    def first_job_stops(job):
        seen.append(job["run"])
        raise Stop

    tracemalloc.start()
    try:
        with pytest.raises(Stop):
            run_montecarlo(spec, tmp_path / "mc", workers=1, job_function=first_job_stops)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert seen == [0]
    assert peak < 5 * 2**20, f"peak {peak / 2**20:.1f} MiB before the first job"
    with pytest.raises(ValueError, match="at most 1,000,000"):
        MonteCarloSpec(preset("crossing"), runs=MAX_RUNS + 1)


def test_a_pool_takes_jobs_from_the_plan_a_few_at_a_time(tmp_path):
    """With 2 workers, when the first record is stored at most IN_FLIGHT_PER_WORKER·2 + 1
    jobs of a 10⁶-job plan have been made."""
    made = []

    def counting(i):
        made.append(i)
        return make(i)

    class StopAfterFirst(JobStore):
        def save(self, job, record):
            raise Stop(len(made))

    store = StopAfterFirst(tmp_path, JsonRecords())
    with pytest.raises(Stop) as e:
        run_jobs(JobPlan(10**6, counting), double, store, workers=2)
    assert e.value.args[0] <= IN_FLIGHT_PER_WORKER * 2 + 1


def test_cli_runs_bound_is_the_spec_bound(tmp_path):
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    r = CliRunner().invoke(cli, ["montecarlo", "crossing", "--runs", str(MAX_RUNS + 1),
                                 "--out", str(tmp_path / "mc")])
    from mhtrack.bounds import show

    assert show(MAX_RUNS) == "1e6"
    assert r.exit_code == 2 and "--runs" in r.stderr and "1e6]" in r.stderr
    assert not (tmp_path / "mc").exists()
