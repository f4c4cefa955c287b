"""The executor interface: JSON Lines as jobs finish, resumable, failures recorded, not fatal."""

import importlib.util
import json
import os

import pytest

from tg_drake.errors import TgDrakeError
from tg_drake.executor import (
    WORKER_DIED,
    Job,
    LocalExecutor,
    finished_jobs,
    make_executor,
    run_jobs,
)


def square(payload):
    """A batch job: one record per number."""
    if payload == "boom":
        raise RuntimeError("solver failed")
    if payload == "die":
        os._exit(3)  # kills the worker process, as a crash in native code would
    return [{"x": x, "y": x * x, "pid": os.getpid()} for x in payload]


def read(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


@pytest.fixture(scope="module")
def pool():
    return LocalExecutor(workers=2)


def test_results_stream_to_jsonl_and_a_rerun_skips_them(tmp_path, pool):
    out = tmp_path / "r.jsonl"
    jobs = [Job(f"j{i}", [2 * i, 2 * i + 1]) for i in range(6)]
    summary = run_jobs(square, jobs[:4], out=out, executor=pool, progress=False)
    assert (summary.n_ran, summary.n_skipped, summary.n_records, summary.n_errors) == (4, 0, 8, 0)
    rows = read(out)
    assert sorted((r["job"], r["x"], r["y"]) for r in rows) == [
        (f"j{x // 2}", x, x * x) for x in range(8)]
    assert os.getpid() not in {r["pid"] for r in rows}  # ran in worker processes, not here

    summary = run_jobs(square, jobs, out=out, executor=pool, progress=False)
    assert (summary.n_ran, summary.n_skipped, summary.n_records) == (2, 4, 4)
    assert sorted(r["x"] for r in read(out)) == list(range(12))  # nothing ran twice


def test_a_failing_job_is_recorded_and_does_not_stop_the_others(tmp_path, pool):
    out = tmp_path / "r.jsonl"
    jobs = [Job("a", [1]), Job("bad", "boom"), Job("b", [2])]
    summary = run_jobs(square, jobs, out=out, executor=pool, progress=False)
    assert summary.n_errors == 1
    by_job = {r["job"]: r for r in read(out)}
    assert by_job["bad"]["status"] == "error"
    assert by_job["bad"]["reason"].startswith("RuntimeError: solver failed (test_executor.py:")
    assert by_job["a"]["y"] == 1 and by_job["b"]["y"] == 4
    # Errors count as finished unless asked to retry them.
    assert finished_jobs(out) == {"a", "b", "bad"}
    assert finished_jobs(out, retry_errors=True) == {"a", "b"}


def test_a_job_that_kills_its_worker_is_found_and_recorded(tmp_path, pool):
    out = tmp_path / "r.jsonl"
    jobs = [Job(f"ok{i}", [i]) for i in range(5)] + [Job("die", "die")] + [Job("last", [9])]
    summary = run_jobs(square, jobs, out=out, executor=pool, progress=False)
    by_job = {r["job"]: r for r in read(out)}
    assert set(by_job) == {f"ok{i}" for i in range(5)} | {"die", "last"}
    assert by_job["die"] == {"job": "die", "status": "error", "reason": WORKER_DIED}
    assert [by_job[f"ok{i}"]["y"] for i in range(5)] == [0, 1, 4, 9, 16]
    assert summary.n_errors == 1 and summary.n_ran == 7


def test_a_torn_last_line_is_ignored_and_rerun(tmp_path):
    out = tmp_path / "r.jsonl"
    out.write_text(json.dumps({"job": "a", "x": 1, "y": 1}) + "\n" + '{"job": "b", "x"')
    assert finished_jobs(out) == {"a"}
    summary = run_jobs(square, [Job("a", [1]), Job("b", [3])], out=out,
                       executor=LocalExecutor(workers=0), progress=False)
    assert summary.n_ran == 1
    lines = out.read_text().splitlines()
    assert json.loads(lines[-1]) == {"job": "b", "x": 3, "y": 9, "pid": os.getpid()}


def test_bad_executor_requests_are_clear_errors():
    with pytest.raises(TgDrakeError, match="unknown executor 'dask'; allowed: local, ray"):
        make_executor("dask")
    with pytest.raises(TgDrakeError, match="is for the ray executor"):
        make_executor("local", address="auto")
    with pytest.raises(TgDrakeError, match="job keys must be unique"):
        run_jobs(square, [Job("a", [1]), Job("a", [2])], out=None, executor=None)


@pytest.mark.skipif(importlib.util.find_spec("ray") is not None, reason="ray is installed")
def test_ray_executor_without_ray_tells_how_to_install_it():
    with pytest.raises(TgDrakeError, match=r"pip install 'tg_drake\[ray\]'"):
        make_executor("ray", address="auto")
