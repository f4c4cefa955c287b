"""The executor interface: JSON Lines as jobs finish, resumable, failures recorded, not fatal."""

import importlib.util
import json
import os
import re
import signal
import socket
import subprocess
import sys
import textwrap
import time

import pytest

from tg_drake.errors import OutputError, TgDrakeError
from tg_drake.executor import (
    RAY_ATTEMPTS,
    RAY_DRIVER_FILE,
    WORKER_DIED,
    Job,
    LocalExecutor,
    finished_jobs,
    make_executor,
    read_records,
    remove_stale_ray_folders,
    run_jobs,
)


def square(payload):
    """A batch job: one record per number."""
    if payload == "boom":
        raise RuntimeError("solver failed")
    if payload == "die":
        os._exit(3)  # kills the worker process, as a crash in native code would
    if isinstance(payload, dict):  # the pair of test_jobs_rerun_after_their_worker_died...
        started = os.path.join(payload["folder"], "wait_started")
        if payload["role"] == "die":
            while not os.path.exists(started):  # both in flight
                time.sleep(0.01)
            os._exit(3)
        if os.path.exists(started):  # run again, alone
            return {"waited": True}
        open(started, "w").close()
        time.sleep(600)  # s: in flight until the pool breaks and its worker is terminated
    return [{"x": x, "y": x * x, "pid": os.getpid()} for x in payload]


def read(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


WHERE = ("worker_pid", "rss_mb", "wall_s")  # where a job ran: in every record the executor writes


def core(record):
    """A record without where it ran."""
    return {k: v for k, v in record.items() if k not in WHERE}


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
    assert all(r["worker_pid"] == r["pid"] and r["rss_mb"] > 1 and r["wall_s"] >= 0 for r in rows)

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
    died = {k: v for k, v in core(by_job["die"]).items() if k != "attempts"}  # alone or with others
    assert died == {"job": "die", "status": "error", "reason": WORKER_DIED}
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
    assert core(json.loads(lines[-1])) == {"job": "b", "x": 3, "y": 9, "pid": os.getpid()}
    assert len(lines) == 2  # the torn line was cut off, not left in the file


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


def test_a_torn_last_line_cut_inside_a_character_is_cut_off(tmp_path):
    out = tmp_path / "r.jsonl"
    good = json.dumps({"job": "a", "x": 1, "y": 1}) + "\n"
    out.write_bytes(good.encode() + '{"job": "b", "name": "é'.encode()[:-1])  # half of "é"
    assert read_records(out) == [{"job": "a", "x": 1, "y": 1}]
    run_jobs(square, [Job("a", [1])], out=out, executor=LocalExecutor(workers=0),
             progress=False)
    assert out.read_text() == good


@pytest.mark.parametrize("content, line, message", [
    ('{"job": "a"}\n[1, 2]\n', 2, 'not a record of a sweep .expected a JSON object with a "job"'),
    ('{"job": "a"}\n{"x": 1}\n', 2, 'not a record of a sweep'),
    ('{"job": 3}\n', 1, 'not a record of a sweep'),
    ('{"job": "a", "x\n{"job": "b"}\n', 1, r"not a JSON record \(Unterminated string"),
    ('{"job": "a"}\n{"job": "b"}\nnot json\n', 3, "not a JSON record"),
    (b'{"job": "a"}\n\xff\xfe{"job": "b"}\n', 2, "not UTF-8 text .byte 1 of the line"),
])
def test_a_malformed_results_file_is_a_clear_error_naming_the_line(tmp_path, content, line,
                                                                    message):
    out = tmp_path / "r.jsonl"
    if isinstance(content, bytes):
        out.write_bytes(content)
    else:
        out.write_text(content)
    before = out.read_bytes()
    for read in (read_records, finished_jobs,
                 lambda p: run_jobs(square, [Job("c", [1])], out=p,
                                    executor=LocalExecutor(workers=0), progress=False)):
        with pytest.raises(OutputError, match=f"^{out}:{line}: {message}"):
            read(out)
    assert out.read_bytes() == before  # nothing appended to a file that is not ours


def test_a_results_path_that_is_a_folder_is_a_clear_error(tmp_path):
    with pytest.raises(OutputError, match=f"^{tmp_path}: the results file is a folder"):
        run_jobs(square, [Job("a", [1])], out=tmp_path, executor=LocalExecutor(workers=0),
                 progress=False)
    below_a_file = tmp_path / "file" / "r.jsonl"
    below_a_file.parent.write_text("")
    with pytest.raises(OutputError, match=f"^{below_a_file}: the results file cannot be written"):
        run_jobs(square, [Job("a", [1])], out=below_a_file, executor=LocalExecutor(workers=0),
                 progress=False)


def test_jobs_rerun_after_their_worker_died_record_their_attempts(tmp_path, pool):
    out = tmp_path / "r.jsonl"
    # "wait" is in flight when "die" kills its worker: each is run again alone.
    jobs = [Job(role, {"role": role, "folder": str(tmp_path)}) for role in ("wait", "die")]
    summary = run_jobs(square, jobs, out=out, executor=pool, progress=False)
    by_job = {r["job"]: r for r in read(out)}
    assert core(by_job["wait"]) == {"job": "wait", "waited": True, "attempts": 2}
    assert core(by_job["die"]) == {"job": "die", "status": "error", "reason": WORKER_DIED,
                             "attempts": 2}
    assert summary.n_errors == 1


def test_a_negative_number_of_workers_is_refused():
    for workers in (-1, -4):
        with pytest.raises(TgDrakeError, match="must be a number of processes ≥ 1, or 0 to run "
                                               "the jobs in this process"):
            make_executor("local", workers=workers)
    assert make_executor("local", workers=0).workers == 0  # in this process, for debugging


SWEEP = """
import os, sys, time
from pathlib import Path
from tg_drake.executor import Job, LocalExecutor, run_jobs

def job(folder):
    Path(folder, str(os.getpid())).touch()
    time.sleep(300)  # s: far longer than the test waits
    return {}

if __name__ == "__main__":
    folder = sys.argv[1]
    run_jobs(job, [Job(str(i), folder) for i in range(2)], out=Path(folder).parent / "r.jsonl",
             executor=LocalExecutor(workers=2), progress=False)
"""


def _alive(pid):
    """Whether process `pid` runs (a zombie awaiting its reaper counts as gone)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="reads /proc")
def test_workers_die_with_a_killed_parent(tmp_path):
    script = tmp_path / "sweep.py"
    script.write_text(textwrap.dedent(SWEEP))
    pids = tmp_path / "pids"
    pids.mkdir()
    parent = subprocess.Popen([sys.executable, str(script), str(pids)])
    try:
        deadline = time.monotonic() + 120  # s: spawning two workers on a loaded machine
        while len(list(pids.iterdir())) < 2:
            assert parent.poll() is None, "the sweep ended before its workers started"
            assert time.monotonic() < deadline, "the workers did not start"
            time.sleep(0.05)
    finally:
        parent.kill()  # SIGKILL: no clean-up runs in the parent
        parent.wait()
    workers = [int(p.name) for p in pids.iterdir() if p.name.isdigit()]
    assert len(workers) == 2
    deadline = time.monotonic() + 30  # s: the bound of a failure, far above the ~0 s it takes
    while any(map(_alive, workers)) and time.monotonic() < deadline:
        time.sleep(0.05)
    alive = [pid for pid in workers if _alive(pid)]
    for pid in alive:
        os.kill(pid, signal.SIGKILL)
    assert not alive, "workers outlived their killed parent"


# --- Ray: addresses are checked before Ray starts -------------------------------------------

ray_installed = pytest.mark.skipif(importlib.util.find_spec("ray") is None,
                                   reason="ray is not installed")


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@ray_installed
@pytest.mark.parametrize("address", ["nonsense", "localhost", "host:", ":6379", "host:port",
                                     "host:70000", "http://host:6379", "ray://", "a b:1"])
def test_a_malformed_ray_address_is_a_clear_error(address):
    with pytest.raises(TgDrakeError, match="^malformed Ray address .*expected host:port"):
        make_executor("ray", address=address)


@ray_installed
def test_an_unreachable_ray_address_is_a_clear_error(monkeypatch):
    monkeypatch.delenv("RAY_ADDRESS", raising=False)
    port = _free_port()
    with pytest.raises(TgDrakeError, match=f"^no Ray cluster at --address 127.0.0.1:{port}: "
                                           "Connection refused"):
        make_executor("ray", address=f"127.0.0.1:{port}")
    monkeypatch.setenv("RAY_ADDRESS", f"127.0.0.1:{port}")  # read when no address is given
    with pytest.raises(TgDrakeError, match=f"no Ray cluster at --address 127.0.0.1:{port}"):
        make_executor("ray")


@ray_installed
@pytest.mark.parametrize("server, reason", [
    ("close", "(it closed the connection .not a Ray GCS.|Connection reset by peer)"),
    ("http1", "(it closed the connection .not a Ray GCS.|Connection reset by peer)"),
    ("silent", "no answer within 3 s"),
])
def test_an_address_where_something_else_answers_is_a_clear_error(server, reason):
    """A proxy or another server that accepts any connection is not taken for a cluster."""
    import threading

    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen()
    port = listener.getsockname()[1]

    def serve():
        connection, _ = listener.accept()
        if server == "http1":
            connection.recv(1024)
            connection.sendall(b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n")
        if server != "silent":
            connection.close()
        else:
            time.sleep(5)  # s: longer than the probe waits

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        with pytest.raises(TgDrakeError, match=f"^no Ray cluster at --address 127.0.0.1:{port}: "
                                               f"{reason}"):
            make_executor("ray", address=f"127.0.0.1:{port}")
    finally:
        listener.close()


@ray_installed
def test_address_auto_with_no_cluster_or_a_stale_one_is_a_clear_error(tmp_path, monkeypatch):
    import ray._private.services as services

    monkeypatch.delenv("RAY_ADDRESS", raising=False)
    monkeypatch.setenv("RAY_TMPDIR", str(tmp_path))  # where Ray records the last cluster
    monkeypatch.setattr(services, "find_gcs_addresses", frozenset)  # no GCS process running
    with pytest.raises(TgDrakeError, match="^--address auto: no Ray cluster found on this "
                                           "machine.*ray start --head"):
        make_executor("ray", address="auto")
    (tmp_path / "ray").mkdir()
    port = _free_port()
    (tmp_path / "ray" / "ray_current_cluster").write_text(f"127.0.0.1:{port}\n")  # crashed
    with pytest.raises(TgDrakeError, match=rf"^no Ray cluster at --address auto \([0-9.]+:"
                                           rf"{port}\): Connection refused"):
        make_executor("ray", address="auto")


@ray_installed
@pytest.mark.parametrize("workers", [0, -1])
def test_ray_refuses_a_number_of_jobs_in_flight_below_one(workers):
    with pytest.raises(TgDrakeError, match="with the ray executor is the number of jobs in "
                                           "flight, ≥ 1"):
        make_executor("ray", workers=workers)


@ray_installed
@pytest.mark.slow
def test_a_local_ray_instance_is_the_sweeps_own_and_counts_attempts(tmp_path, monkeypatch):
    """A stale cluster recorded in the shared temp folder is not joined; the instance runs in a
    temp folder of its own, removed after; a job that kills its Ray worker is retried, counted."""
    import ray
    from ray import cloudpickle

    cloudpickle.register_pickle_by_value(sys.modules[__name__])  # Ray workers lack tests/
    monkeypatch.delenv("RAY_ADDRESS", raising=False)
    monkeypatch.setenv("RAY_TMPDIR", str(tmp_path / "shared"))
    (tmp_path / "shared" / "ray").mkdir(parents=True)
    (tmp_path / "shared" / "ray" / "ray_current_cluster").write_text(f"127.0.0.1:{_free_port()}")
    before = set(os.listdir("/tmp"))
    out = tmp_path / "r.jsonl"
    summary = run_jobs(square, [Job("a", [1, 2]), Job("die", "die")], out=out,
                       executor=make_executor("ray", workers=2), progress=False)
    by_job = {}
    for r in read(out):
        by_job.setdefault(r["job"], []).append(r)
    assert [(r.get("x"), r.get("y")) for r in by_job["a"]] == [(1, 1), (2, 4)], by_job["a"]
    assert [core(r) for r in by_job["die"]] == [{"job": "die", "status": "error",
                                               "attempts": RAY_ATTEMPTS,
                              "reason": f"{WORKER_DIED}: " + by_job["die"][0]["reason"].split(
                                  ": ", 1)[1]}]
    assert summary.n_errors == 1
    assert not ray.is_initialized()  # shut down after the sweep
    assert not any(name.startswith("tg-ray-") for name in set(os.listdir("/tmp")) - before)


# --- Progress: counts per outcome, a job's warnings above the bar ---------------------------

def noisy(payload):
    """A job that writes besides its result: a Python warning, a Drake-style log line, a line
    from native code on fd 2; its outcome is the payload."""
    import logging
    import warnings

    if payload == "boom":
        raise RuntimeError("solver failed")
    warnings.warn(f"mesh has {len(payload)} degenerate faces", UserWarning, stacklevel=1)
    logging.getLogger("drake").warning("contact penetration is large")
    os.write(2, b"native: vtk says hello\n")
    return {"outcome": {"status": payload}}


def status_of(records):
    return records[0]["outcome"]["status"]


BAR = re.compile(r"r\.jsonl: +\d+%\|.*\| \d+/\d+ \[[\d:]+, ETA [\d:?]+, .*\]")


def test_the_bar_counts_outcomes_and_a_workers_warnings_leave_its_lines_intact(tmp_path, capfd):
    out = tmp_path / "r.jsonl"
    jobs = [Job(f"j{i}", s) for i, s in enumerate(["placed", "failed", "placed", "boom"])]
    summary = run_jobs(noisy, jobs, out=out, executor=LocalExecutor(workers=2),
                       outcome_of=status_of)
    assert summary.counts == {"placed": 2, "failed": 1, "error": 1}
    err = capfd.readouterr().err
    lines = [line for line in re.split(r"[\r\n]", err) if line.strip()]
    bars = [line for line in lines if line.startswith("r.jsonl:")]
    assert bars and all(BAR.fullmatch(line.strip()) for line in bars), bars
    assert "placed=2" in bars[-1] and "failed=1" in bars[-1] and "error=1" in bars[-1]
    assert "100%" in bars[-1] and "ETA 00:00" in bars[-1]
    others = [line for line in lines if not line.startswith("r.jsonl:")]
    # Each distinct line once, on a line of its own above the bar, naming its job.
    assert sum("native: vtk says hello" in line for line in others) == 1
    assert sum("contact penetration is large" in line for line in others) == 1
    assert all(re.match(r"j\d: ", line) for line in others), others
    by_job = {r["job"]: r for r in read(out)}
    for key in ("j0", "j1", "j2"):  # and every line in each job's record
        log = by_job[key]["log"]
        assert any(line.startswith("UserWarning: mesh has 6 degenerate faces") for line in log)
        assert "[drake] WARNING: contact penetration is large" in log
        assert "native: vtk says hello" in log
    assert "log" not in by_job["j3"]


def test_a_job_in_this_process_keeps_its_warnings_in_its_record(tmp_path, capfd):
    out = tmp_path / "r.jsonl"
    run_jobs(noisy, [Job("a", "placed")], out=out, executor=LocalExecutor(workers=0),
             progress=False)
    (record,) = read(out)
    assert re.fullmatch(r"UserWarning: mesh has 6 degenerate faces \(test_executor\.py:\d+\)",
                        record["log"][0])
    assert record["log"][1] == "[drake] WARNING: contact penetration is large"
    err = capfd.readouterr().err
    assert "degenerate" not in err and "penetration" not in err  # not on stderr: in the record
    assert record["worker_pid"] == os.getpid()


def thread_settings(_):
    from tg_drake.executor import THREAD_VARIABLES

    return {name: os.environ.get(name) for name in THREAD_VARIABLES}


def test_pool_workers_get_their_share_of_the_cores_for_thread_pools(tmp_path, monkeypatch):
    monkeypatch.delenv("OMP_NUM_THREADS", raising=False)
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "3")  # the user's setting is kept
    out = tmp_path / "r.jsonl"
    run_jobs(thread_settings, [Job("a", None)], out=out, executor=LocalExecutor(workers=2),
             progress=False)
    (record,) = read(out)
    assert record["OMP_NUM_THREADS"] == str(max(1, (os.cpu_count() or 1) // 2))
    assert record["OPENBLAS_NUM_THREADS"] == "3"


def test_a_killed_drivers_ray_folder_is_removed_by_the_next_start(tmp_path):
    """A driver killed with kill -9 leaves its local Ray temp folder (Ray's processes exit on
    their own); the next local start removes the folders whose driver is gone, and only those."""
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    folders = {}
    for name, pid in (("dead", dead.pid), ("alive", os.getpid()), ("unmarked", None)):
        d = tmp_path / f"tg-ray-{name}"
        (d / "session_latest").mkdir(parents=True)
        if pid is not None:
            (d / RAY_DRIVER_FILE).write_text(f"{pid}\n")
        folders[name] = d
    (tmp_path / "other-dead").mkdir()  # not ours: never looked at
    assert remove_stale_ray_folders(tmp_path) == [folders["dead"]]
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "other-dead", "tg-ray-alive", "tg-ray-unmarked"]
