"""The job runner (mhtrack.experiments.jobs): store, resume, executors, seeds."""

import json

import pytest

from mhtrack.experiments.jobs import (
    COMPACT,
    SPACED,
    Job,
    JobStore,
    JsonRecords,
    ParquetRecords,
    params_hash,
    run_jobs,
    run_seed,
    run_seeds,
)


def square(job):
    """A deterministic job function (top level: pickles to a pool)."""
    if job["x"] == 13:
        raise RuntimeError("unlucky 13")
    return {"x": job["x"], "square": job["x"] ** 2, "seed": run_seed(job["seed"], job["x"],
                                                                     "spawn")}


def jobs_of(xs, seed=0):
    return [Job.of(f"part-{x % 2}/x-{x}", {"x": x, "seed": seed}) for x in xs]


def stored(store, jobs):
    return {j.key: store.path(j.key).read_bytes() for j in jobs if store.is_done(j)}


# ---------------------------------------------------------------------------- seeds
def test_golden_seeds_of_the_existing_studies():
    """The seeds the studies used before the runner was unified (montecarlo's run_seed,
    initiation.runs.run_seeds), pinned: changing them would change every result."""
    assert [run_seed(5, i, "spawn") for i in range(3)] == [
        7829437886636254564, 3462322709277726755, 862719652024447009]
    assert run_seeds(7, 3, "words") == [2083679832, 3939563265, 4185785210]


@pytest.mark.parametrize("stream", ["spawn", "words"])
def test_seeds_depend_on_seed_and_run_only(stream):
    many = run_seeds(11, 50, stream)
    assert len(set(many)) == 50  # distinct across runs
    assert run_seeds(11, 7, stream) == many[:7]  # not on the number of runs
    assert [run_seed(11, r, stream) for r in (0, 9, 49)] == [many[0], many[9], many[49]]
    assert run_seeds(12, 50, stream) != many
    assert all(0 <= s < 2**63 for s in many)


def test_seed_arguments_are_checked():
    with pytest.raises(ValueError, match="runs"):
        run_seeds(1, 0, "words")
    with pytest.raises(ValueError, match="seed"):
        run_seed(-1, 0, "spawn")
    with pytest.raises(ValueError, match="stream"):
        run_seeds(1, 2, "other")  # type: ignore[arg-type]


# ---------------------------------------------------------------------------- jobs
def test_hash_is_sha256_of_sorted_json():
    import hashlib

    p = {"b": [1, 2.5], "a": "x"}
    assert params_hash(p) == hashlib.sha256(b'{"a":"x","b":[1,2.5]}').hexdigest()
    assert params_hash(p, SPACED) == hashlib.sha256(b'{"a": "x", "b": [1, 2.5]}').hexdigest()
    assert Job.of("k", p, COMPACT).as_dict() == {**p, "job_hash": params_hash(p)}


# ---------------------------------------------------------------------------- runner
@pytest.mark.parametrize("fmt", [JsonRecords(), ParquetRecords()])
def test_run_store_and_resume(tmp_path, fmt):
    store = JobStore(tmp_path, fmt)
    jobs = jobs_of(range(6))
    first = run_jobs(jobs, square, store, workers=1)
    assert (first.computed, first.skipped, first.errors) == (6, 0, {})
    for j in jobs:
        assert store.path(j.key) == tmp_path / f"part-{j.params['x'] % 2}" / \
            f"x-{j.params['x']}{fmt.suffix}"
        assert store.load(j)["square"] == j.params["x"] ** 2
    before = {j.key: store.path(j.key).stat().st_mtime_ns for j in jobs}
    again = run_jobs(jobs, square, store, workers=1)
    assert (again.computed, again.skipped) == (0, 6)
    assert before == {j.key: store.path(j.key).stat().st_mtime_ns for j in jobs}
    assert not [p for p in tmp_path.rglob(".*") if p.is_file()]  # no temporary file left


def test_one_and_two_workers_store_identical_records(tmp_path):
    jobs = jobs_of(range(8), seed=3)
    one, two = JobStore(tmp_path / "one", JsonRecords()), JobStore(tmp_path / "two",
                                                                   JsonRecords())
    run_jobs(jobs, square, one, workers=1)
    run_jobs(jobs, square, two, workers=2)
    assert stored(one, jobs) == stored(two, jobs)
    assert len(stored(one, jobs)) == 8


def test_corrupted_partial_or_foreign_files_are_recomputed(tmp_path):
    store = JobStore(tmp_path, JsonRecords())
    jobs = jobs_of(range(4))
    run_jobs(jobs, square, store, workers=1)
    good = stored(store, jobs)
    store.path(jobs[0].key).write_text('{"job": {"x": 0, "job_ha')  # cut short
    store.path(jobs[1].key).write_bytes(b"\x00garbage")
    other = json.loads(store.path(jobs[2].key).read_text())
    other["job"]["job_hash"] = "0" * 64  # a file of other parameters
    store.path(jobs[2].key).write_text(json.dumps(other))
    calls = []

    def counting(job):
        calls.append(job["x"])
        return square(job)

    r = run_jobs(jobs, counting, store, workers=1)
    assert sorted(calls) == [0, 1, 2] and (r.computed, r.skipped) == (3, 1)
    assert stored(store, jobs) == good


def test_parquet_store_partial_file_is_recomputed(tmp_path):
    store = JobStore(tmp_path, ParquetRecords())
    jobs = jobs_of(range(2))
    run_jobs(jobs, square, store, workers=1)
    p = store.path(jobs[1].key)
    p.write_bytes(p.read_bytes()[:20])
    assert store.stored_hash(jobs[1]) is None
    assert run_jobs(jobs, square, store, workers=1).computed == 1
    assert store.load(jobs[1]) == {"x": 1, "square": 1, "seed": run_seed(0, 1, "spawn")}


@pytest.mark.parametrize("workers", [1, 2])
def test_a_failed_job_leaves_its_traceback_and_is_retried(tmp_path, workers):
    store = JobStore(tmp_path, JsonRecords())
    jobs = jobs_of([12, 13, 14])
    r = run_jobs(jobs, square, store, workers=workers)
    assert list(r.errors) == [jobs[1].key] and "unlucky 13" in r.errors[jobs[1].key]
    assert "unlucky 13" in store.error(jobs[1]) and not store.path(jobs[1].key).exists()
    assert store.is_done(jobs[0]) and store.is_done(jobs[2])
    # a rerun retries only the failed job; its success clears the error file
    fixed = run_jobs(jobs, lambda job: {"x": job["x"]}, store, workers=1)
    assert (fixed.computed, fixed.skipped, fixed.errors) == (1, 2, {})
    assert store.error(jobs[1]) is None and store.load(jobs[1]) == {"x": 13}


def test_an_interruption_loses_no_finished_job(tmp_path):
    store = JobStore(tmp_path, JsonRecords())
    jobs = jobs_of(range(5))
    done = []

    def interrupted(job):
        if len(done) == 2:
            raise KeyboardInterrupt
        done.append(job["x"])
        return square(job)

    with pytest.raises(KeyboardInterrupt):
        run_jobs(jobs, interrupted, store, workers=1)
    assert sum(store.is_done(j) for j in jobs) == 2
    assert run_jobs(jobs, square, store, workers=1).computed == 3


def test_dask_gives_the_same_records(tmp_path):
    distributed = pytest.importorskip("distributed")
    jobs = jobs_of(range(4), seed=9)
    local = JobStore(tmp_path / "local", JsonRecords())
    run_jobs(jobs, square, local, workers=1)
    dask = JobStore(tmp_path / "dask", JsonRecords())
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        r = run_jobs(jobs, square, dask, executor="dask", scheduler=cluster.scheduler_address)
    assert r.computed == 4 and stored(dask, jobs) == stored(local, jobs)


def test_bad_arguments_are_refused(tmp_path):
    store = JobStore(tmp_path, JsonRecords())
    with pytest.raises(ValueError, match="share a key"):
        run_jobs([Job.of("a", {"x": 1}), Job.of("a", {"x": 2})], square, store)
    with pytest.raises(ValueError, match="executor"):
        run_jobs(jobs_of([1]), square, store, executor="threads")
    with pytest.raises(ValueError, match="scheduler"):
        run_jobs(jobs_of([1]), square, store, executor="dask")
    with pytest.raises(ValueError, match="workers"):
        run_jobs(jobs_of([1]), square, store, workers=0)
