"""Runs many independent jobs and streams their results to JSON Lines, resumably.

One interface for every sweep (grasp-data collection, scenario evaluation):

    executor = make_executor("local", workers=2)          # or "ray", address="auto"
    summary = run_jobs(fn, jobs, out=Path("data/x.jsonl"), executor=executor)

- A `Job` has a stable `key` and a picklable `payload`; `fn(payload)` returns one JSON-serialisable
  dict or a list of them (a job may be a batch). Every record is written as one line with the
  job's key under "job", as soon as its job finishes, and flushed.
- A rerun reads the file first and skips every job that already has a line.
- A job that raises is recorded as {"job": key, "status": "error", "reason": "..."}; one that kills
  its worker process (a segfault, an abort in native code) is found by rerunning the jobs that were
  in flight one at a time, and is recorded with the reason "worker process died". Neither stops
  the sweep.

`LocalExecutor` is a process pool (spawned workers; `workers=0` runs in this process, for
debugging). `RayExecutor` submits to a Ray cluster; Ray is an optional dependency
(`pip install 'tg_drake[ray]'`) and is imported only when that executor is made.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import traceback
from abc import ABC, abstractmethod
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tg_drake.errors import TgDrakeError, unknown_name

EXECUTORS = ("local", "ray")
WORKER_DIED = "worker process died"


@dataclass(frozen=True)
class Job:
    """One unit of work: `key` names it in the output (stable across reruns)."""

    key: str
    payload: Any


@dataclass(frozen=True)
class Outcome:
    """What a job gave: its records, or the reason it failed."""

    records: list[dict] | None
    error: str | None = None


@dataclass
class RunSummary:
    n_jobs: int  # jobs asked for
    n_skipped: int  # already in the output file
    n_ran: int  # run now
    n_errors: int  # of those run now, jobs recorded as errors
    n_records: int  # lines written now


def call_job(fn: Callable[[Any], Any], payload: Any) -> Outcome:
    """Runs `fn(payload)` and turns its result or exception into an Outcome (runs in a worker)."""
    try:
        result = fn(payload)
    except Exception as e:  # noqa: BLE001 - every failure of a job is data, not a crash.
        last = traceback.extract_tb(e.__traceback__)[-1]
        where = f" ({os.path.basename(last.filename)}:{last.lineno})" if last else ""
        return Outcome(None, f"{type(e).__name__}: {e}{where}")
    records = result if isinstance(result, list) else [result]
    if not all(isinstance(r, dict) for r in records):
        return Outcome(None, f"job returned {type(result).__name__}, not a dict or list of dicts")
    return Outcome(records)


class Executor(ABC):
    """Runs `call_job(fn, job.payload)` for every job and yields (job, Outcome) as they finish."""

    @abstractmethod
    def imap_unordered(self, fn: Callable[[Any], Any],
                       jobs: Iterable[Job]) -> Iterator[tuple[Job, Outcome]]:
        ...


class LocalExecutor(Executor):
    """A pool of `workers` spawned processes; `workers=0` runs the jobs in this process."""

    def __init__(self, workers: int | None = None, *, max_tasks_per_child: int | None = None):
        workers = (os.cpu_count() or 1) if workers is None else workers
        if workers < 0:
            raise TgDrakeError(f"workers must be ≥ 0, got {workers}")
        self.workers = workers
        self.max_tasks_per_child = max_tasks_per_child  # recycle workers that leak memory

    def _pool(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(self.workers, mp_context=multiprocessing.get_context("spawn"),
                                   max_tasks_per_child=self.max_tasks_per_child)

    def imap_unordered(self, fn, jobs):
        if self.workers == 0:
            for job in jobs:
                yield job, call_job(fn, job.payload)
            return
        pending = deque(jobs)
        suspects: deque[Job] = deque()  # in flight when a worker died: rerun alone
        while pending or suspects:
            pool = self._pool()
            in_flight: dict = {}
            try:
                while pending or suspects or in_flight:
                    # Suspects run one at a time so that the one that kills a worker is known.
                    while not in_flight and suspects:
                        job = suspects.popleft()
                        in_flight[pool.submit(call_job, fn, job.payload)] = job
                    while not suspects and pending and len(in_flight) < 2 * self.workers:
                        job = pending.popleft()
                        in_flight[pool.submit(call_job, fn, job.payload)] = job
                    done, _ = wait(in_flight, return_when=FIRST_COMPLETED)
                    for future in done:
                        outcome = future.result()  # raises BrokenProcessPool if a worker died
                        yield in_flight.pop(future), outcome
            except BrokenProcessPool:
                # Futures that finished before the pool broke keep their results.
                for future, job in list(in_flight.items()):
                    if future.done() and not future.cancelled() and future.exception() is None:
                        del in_flight[future]
                        yield job, future.result()
                if len(in_flight) == 1:
                    (job,) = in_flight.values()
                    yield job, Outcome(None, WORKER_DIED)
                else:
                    suspects.extend(in_flight.values())
            finally:
                pool.shutdown(wait=True, cancel_futures=True)


class RayExecutor(Executor):
    """Jobs as Ray tasks on a cluster (`address`, e.g. "auto") or a local Ray instance (None)."""

    def __init__(self, address: str | None = None, *, max_in_flight: int | None = None):
        try:
            import ray  # optional (the `ray` extra)
        except ImportError:
            raise TgDrakeError(
                "the Ray executor needs Ray, which is not installed: "
                "pip install 'tg_drake[ray]'") from None
        self._ray = ray
        self.address = address
        self.max_in_flight = max_in_flight or 1000  # tasks submitted and not yet finished

    def imap_unordered(self, fn, jobs):
        ray = self._ray
        if not ray.is_initialized():
            ray.init(address=self.address)
        remote = ray.remote(call_job)
        fn_ref = ray.put(fn)
        pending = deque(jobs)
        in_flight: dict = {}
        while pending or in_flight:
            while pending and len(in_flight) < self.max_in_flight:
                job = pending.popleft()
                in_flight[remote.remote(fn_ref, job.payload)] = job
            (ready,), _ = ray.wait(list(in_flight), num_returns=1)
            job = in_flight.pop(ready)
            try:
                outcome = ray.get(ready)
            except ray.exceptions.RayError as e:  # the worker or its node died
                outcome = Outcome(None, f"{WORKER_DIED}: {type(e).__name__}")
            yield job, outcome


def make_executor(kind: str = "local", *, workers: int | None = None,
                  address: str | None = None) -> Executor:
    """The executor named `kind`: "local" (`workers` processes, default one per core) or "ray"
    (the cluster at `address`, or a local Ray; at most `workers` jobs in flight, if given)."""
    if kind == "local":
        if address is not None:
            raise TgDrakeError(f"an address ({address!r}) is for the ray executor, not local")
        return LocalExecutor(workers)
    if kind == "ray":
        return RayExecutor(address, max_in_flight=workers)
    raise unknown_name("executor", kind, EXECUTORS, error=TgDrakeError)


def finished_jobs(out: Path, *, retry_errors: bool = False) -> set[str]:
    """Keys of the jobs that already have a line in `out` (a torn last line is ignored)."""
    done: set[str] = set()
    if not out.exists():
        return done
    with out.open() as f:
        for line in f:
            try:
                record = json.loads(line)
            except json.JSONDecodeError:
                continue  # the last line of a run that was killed mid-write
            if retry_errors and record.get("status") == "error":
                continue
            if "job" in record:
                done.add(record["job"])
    return done


def run_jobs(fn: Callable[[Any], Any], jobs: Iterable[Job], *, out: Path, executor: Executor,
             retry_errors: bool = False, progress: bool = True) -> RunSummary:
    """Runs the jobs not yet in `out` and appends their records to it as they finish.

    `fn` must be importable by name (a module-level function) for process and Ray executors.
    """
    jobs = list(jobs)
    keys = [job.key for job in jobs]
    if len(set(keys)) != len(keys):
        raise TgDrakeError("job keys must be unique")
    done = finished_jobs(out, retry_errors=retry_errors)
    todo = [job for job in jobs if job.key not in done]
    out.parent.mkdir(parents=True, exist_ok=True)
    summary = RunSummary(len(jobs), len(jobs) - len(todo), 0, 0, 0)
    bar = None
    if progress:
        from tqdm import tqdm  # start-up: this module is on `tg-drake --help`'s path; tqdm ~0.5 s

        bar = tqdm(total=len(todo), desc=out.name, unit="job")
    with out.open("a") as f:
        # A file cut mid-line by a killed run: start on a fresh line.
        if f.tell() > 0:
            with out.open("rb") as r:
                r.seek(-1, os.SEEK_END)
                if r.read(1) != b"\n":
                    f.write("\n")
        for job, outcome in executor.imap_unordered(fn, todo):
            if outcome.error is not None:
                records = [{"status": "error", "reason": outcome.error}]
                summary.n_errors += 1
            else:
                records = outcome.records
            # One write per job: its lines land together.
            f.write("".join(json.dumps({"job": job.key, **r}) + "\n" for r in records))
            f.flush()
            summary.n_ran += 1
            summary.n_records += len(records)
            if bar is not None:
                bar.update(1)
    if bar is not None:
        bar.close()
    return summary
