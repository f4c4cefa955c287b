"""Runs many independent jobs and streams their results to JSON Lines, resumably.

One interface for every sweep (grasp-data collection, scenario evaluation):

    executor = make_executor("local", workers=2)          # or "ray", address="auto"
    summary = run_jobs(fn, jobs, out=Path("data/x.jsonl"), executor=executor)

- A `Job` has a stable `key` and a picklable `payload`; `fn(payload)` returns one JSON-serialisable
  dict or a list of them (a job may be a batch). Every record is written as one line with the
  job's key under "job", as soon as its job finishes, and flushed.
- A rerun reads the file first and skips every job that already has a line. A torn last line (a
  run killed mid-write) is cut off the file; any other line that is not a record (a JSON object
  with a "job" key) is an error naming the file and the line, as is a file that is not UTF-8.
- A job that raises is recorded as {"job": key, "status": "error", "reason": "..."}; one that kills
  its worker process (a segfault, an abort in native code) is found by rerunning the jobs that were
  in flight one at a time, and is recorded with the reason "worker process died". Neither stops
  the sweep. The records of a job that ran more than once (its worker died under it) carry
  "attempts": the number of times it was started.
- Every record says where and how long it ran: `worker_pid`, `rss_mb` (the worker's peak resident
  memory so far [MB]) and `wall_s` (the job's wall time [s]). What a job writes besides its
  result — Python warnings, log records (Drake's C++ log
  lines reach Python's `logging`), and, in a pool or Ray worker, anything written to its stdout or
  stderr by native code — is captured per job and kept in the record's "log" (a list of lines);
  with the progress bar, each distinct line is also printed above the bar (tqdm.write), so the
  bar's lines stay intact.
- The progress bar shows the ETA and, with `outcome_of` (records → a word), counts per word as
  jobs finish ("placed=3 failed=1 error=1").

`LocalExecutor` is a process pool (spawned workers, which die with the process that started them,
each with its share of the cores for its libraries' thread pools; `workers=0` runs in this process,
for debugging). `RayExecutor` submits to a Ray cluster, or
starts a local Ray instance of its own (its own temp folder); an address is checked (its form, then
a connection) before Ray is started. Ray is an optional dependency (`pip install 'tg_drake[ray]'`)
and is imported only when that executor is made.
"""

from __future__ import annotations

import ctypes
import dataclasses
import json
import logging
import multiprocessing
import os
import shutil
import signal
import socket
import sys
import tempfile
import threading
import time
import traceback
import warnings
from abc import ABC, abstractmethod
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tg_drake.errors import OutputError, TgDrakeError, unknown_name
from tg_drake.outputs import check_output_file

try:
    import resource  # POSIX only: the workers' peak memory
except ImportError:
    resource = None

EXECUTORS = ("local", "ray")
WORKER_DIED = "worker process died"
RAY_ATTEMPTS = 3  # times a Ray job is started when its worker or node dies under it
RAY_CONNECT_TIMEOUT_S = 3.0  # s, for the probe of a Ray cluster's address
# Thread pools of the numeric libraries (OpenMP: Open3D, VTK; BLAS: numpy, scikit-learn), sized in
# each pool worker to its share of the cores unless the user set them: workers that each start a
# thread per core wait on one another.
THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                    "BLIS_NUM_THREADS", "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS")
PARENT_POLL_S = 0.5  # s, between a worker's checks that its parent lives (where prctl is missing)
NO_ANSWER = f"no answer within {RAY_CONNECT_TIMEOUT_S:g} s"
MAX_QUOTED = 120  # characters of a bad line quoted in an error
MAX_LOG_LINES = 20  # lines of a job's captured output kept in its record
MAX_LOG_CHARS = 300  # characters of one captured line kept
BAR_FORMAT = ("{desc}: {percentage:3.0f}%|{bar}| {n_fmt}/{total_fmt} "
              "[{elapsed}, ETA {remaining}, {rate_fmt}{postfix}]")


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
    attempts: int = 1  # times the job was started (> 1: its worker died under an earlier one)
    log: tuple[str, ...] = ()  # what the job wrote besides its result (warnings, log lines)
    worker_pid: int | None = None  # the process that ran it (None: its worker died)
    rss_mb: float | None = None  # that process's peak resident memory so far [MB]
    wall_s: float | None = None  # wall time of the job's function [s]


@dataclass
class RunSummary:
    n_jobs: int  # jobs asked for
    n_skipped: int  # already in the output file
    n_ran: int  # run now
    n_errors: int  # of those run now, jobs recorded as errors
    n_records: int  # lines written now
    counts: dict[str, int] = dataclasses.field(default_factory=dict)  # jobs run now per outcome


def call_job(fn: Callable[[Any], Any], payload: Any, capture_fds: bool = False) -> Outcome:
    """Runs `fn(payload)` and turns its result or exception into an Outcome (runs in a worker),
    with what it wrote besides (JobLog). `capture_fds`: this process's stdout and stderr go to a
    file read back after each job (a worker's; never the process that draws the progress bar)."""
    if capture_fds:
        capture_output()
    t0 = time.perf_counter()
    with JobLog() as log:
        try:
            result = fn(payload)
        except Exception as e:  # noqa: BLE001 - every failure of a job is data, not a crash.
            last = traceback.extract_tb(e.__traceback__)[-1]
            where = f" ({os.path.basename(last.filename)}:{last.lineno})" if last else ""
            outcome = Outcome(None, f"{type(e).__name__}: {e}{where}")
        else:
            records = result if isinstance(result, list) else [result]
            outcome = Outcome(records) if all(isinstance(r, dict) for r in records) else Outcome(
                None, f"job returned {type(result).__name__}, not a dict or list of dicts")
    return dataclasses.replace(outcome, log=log.lines, worker_pid=os.getpid(),
                               rss_mb=peak_rss_mb(),
                               wall_s=round(time.perf_counter() - t0, 3))


def peak_rss_mb() -> float | None:
    """This process's peak resident memory so far [MB] (None where `resource` is missing)."""
    if resource is None:
        return None
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB on Linux, bytes on macOS
    return round(peak / (2**20 if sys.platform == "darwin" else 2**10), 1)


_CAPTURED: Any = None  # in a worker: the file its stdout and stderr (fds 1, 2) are sent to


def capture_output() -> None:
    """Sends this process's stdout and stderr (fds 1 and 2: Python's and native code's writes)
    to an unnamed temporary file, read back by JobLog after each job. Once per process."""
    global _CAPTURED
    if _CAPTURED is not None:
        return
    for stream in (sys.stdout, sys.stderr):
        if stream is not None:
            stream.flush()
    f = tempfile.TemporaryFile()
    os.dup2(f.fileno(), 1)
    os.dup2(f.fileno(), 2)
    _CAPTURED = f


def _take_captured() -> list[str]:
    """The lines written to the captured fds since the last call; the file is emptied."""
    if _CAPTURED is None:
        return []
    for stream in (sys.stdout, sys.stderr):
        if stream is not None:
            stream.flush()
    fd = _CAPTURED.fileno()
    size = os.fstat(fd).st_size
    data = os.pread(fd, size, 0) if size else b""
    os.ftruncate(fd, 0)
    os.lseek(fd, 0, os.SEEK_SET)  # shared by fds 1 and 2: the next write starts at 0
    return data.decode("utf-8", "replace").splitlines()


class _LogHandler(logging.Handler):
    def __init__(self, lines: list[str]):
        super().__init__(logging.WARNING)
        self._lines = lines

    def emit(self, record: logging.LogRecord) -> None:
        try:
            self._lines.append(f"[{record.name}] {record.levelname}: {record.getMessage()}")
        except Exception:  # noqa: BLE001 - a bad log call must not fail the job
            self.handleError(record)


class JobLog:
    """Collects what a job writes besides its result: Python warnings (shown as they would be,
    once per place under the default filters), log records of level WARNING and above (Drake's C++
    log lines come through Python's `logging`; while a job runs they reach this collector rather
    than the last-resort handler on stderr), and the lines of the captured fds (capture_output).
    `lines`: at most MAX_LOG_LINES, each at most MAX_LOG_CHARS."""

    def __enter__(self) -> JobLog:
        self._lines: list[str] = []
        self._warnings = warnings.catch_warnings(record=True)
        self._caught = self._warnings.__enter__()
        self._handler = _LogHandler(self._lines)
        logging.getLogger().addHandler(self._handler)
        _take_captured()  # what was written between jobs is not this job's
        self.lines: tuple[str, ...] = ()
        return self

    def __exit__(self, *exc) -> None:
        logging.getLogger().removeHandler(self._handler)
        self._warnings.__exit__(*exc)
        lines = [f"{w.category.__name__}: {w.message} ({os.path.basename(w.filename)}:"
                 f"{w.lineno})" for w in self._caught]
        lines += self._lines + _take_captured()
        lines = [" ".join(line.split()) for line in lines]
        lines = [line if len(line) <= MAX_LOG_CHARS else line[:MAX_LOG_CHARS] + "…"
                 for line in lines if line]
        if len(lines) > MAX_LOG_LINES:
            lines = lines[:MAX_LOG_LINES - 1] + [f"… ({len(lines) - MAX_LOG_LINES + 1} more "
                                                 "lines)"]
        self.lines = tuple(lines)


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
        if not isinstance(workers, int) or workers < 0:
            raise TgDrakeError(f"workers (--workers) must be a number of processes ≥ 1, or 0 to "
                               f"run the jobs in this process (for debugging); got {workers!r}")
        self.workers = workers
        self.max_tasks_per_child = max_tasks_per_child  # recycle workers that leak memory

    def _pool(self) -> ProcessPoolExecutor:
        threads = max(1, (os.cpu_count() or 1) // self.workers)
        pool = ProcessPoolExecutor(self.workers, mp_context=multiprocessing.get_context("spawn"),
                                   max_tasks_per_child=self.max_tasks_per_child,
                                   initializer=start_worker, initargs=(os.getpid(), threads))
        # Start every worker with the pool: one spawned on demand, as the pool's watcher thread
        # has begun to wait, is not watched, and its death (a job that kills it while the other
        # jobs run on) would leave the sweep waiting forever.
        if hasattr(pool, "_safe_to_dynamically_spawn_children"):
            pool._safe_to_dynamically_spawn_children = False
        return pool

    def imap_unordered(self, fn, jobs):
        if self.workers == 0:
            for job in jobs:
                yield job, call_job(fn, job.payload)
            return
        pending = deque(jobs)
        suspects: deque[Job] = deque()  # in flight when a worker died: rerun alone
        attempts: dict[str, int] = {}  # job key → times started

        def submit(pool, queue):
            # A pool broken since the last wait refuses the job: it stays queued, for the next.
            future = pool.submit(call_job, fn, queue[0].payload)
            job = queue.popleft()
            attempts[job.key] = attempts.get(job.key, 0) + 1
            in_flight[future] = job

        def counted(job, outcome):
            return job, dataclasses.replace(outcome, attempts=attempts[job.key])

        while pending or suspects:
            pool = self._pool()
            in_flight: dict = {}
            try:
                while pending or suspects or in_flight:
                    # Suspects run one at a time so that the one that kills a worker is known.
                    while not in_flight and suspects:
                        submit(pool, suspects)
                    while not suspects and pending and len(in_flight) < 2 * self.workers:
                        submit(pool, pending)
                    done, _ = wait(in_flight, return_when=FIRST_COMPLETED)
                    for future in done:
                        outcome = future.result()  # raises BrokenProcessPool if a worker died
                        yield counted(in_flight.pop(future), outcome)
            except BrokenProcessPool:
                # Futures that finished before the pool broke keep their results.
                for future, job in list(in_flight.items()):
                    if future.done() and not future.cancelled() and future.exception() is None:
                        del in_flight[future]
                        yield counted(job, future.result())
                if len(in_flight) == 1:
                    (job,) = in_flight.values()
                    yield counted(job, Outcome(None, WORKER_DIED))
                else:
                    suspects.extend(in_flight.values())
            finally:
                pool.shutdown(wait=True, cancel_futures=True)


def start_worker(parent_pid: int, threads: int = 1) -> None:
    """A pool worker's initializer: it dies with its parent, its output is captured per job (so
    that it never writes over the parent's progress bar), and its numeric libraries' thread pools
    get `threads` threads (its share of the cores; THREAD_VARIABLES the user set are kept). Runs
    before the job's modules, and so numpy and Open3D, are imported."""
    die_with_parent(parent_pid)
    for name in THREAD_VARIABLES:
        os.environ.setdefault(name, str(threads))
    capture_output()


def die_with_parent(parent_pid: int) -> None:
    """A worker's initializer: the worker is killed when the process that started it dies (a
    killed sweep leaves no workers behind). On Linux the kernel does it (prctl PR_SET_PDEATHSIG),
    even while the worker runs native code; elsewhere a thread polls the parent's pid."""
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            pr_set_pdeathsig = 1  # from <linux/prctl.h>
            if libc.prctl(pr_set_pdeathsig, signal.SIGKILL, 0, 0, 0) == 0:
                if os.getppid() != parent_pid:  # the parent died before the call
                    os._exit(1)
                return
        except (OSError, AttributeError):
            pass

    def watch():
        while os.getppid() == parent_pid:
            time.sleep(PARENT_POLL_S)
        os._exit(1)

    threading.Thread(target=watch, name="die-with-parent", daemon=True).start()


RAY_TEMP_PREFIX = "tg-ray-"  # a local Ray instance's own temp folder: <tmp>/tg-ray-XXXXXXXX
RAY_DRIVER_FILE = "driver.pid"  # in it: the pid of the process that started the instance


def remove_stale_ray_folders(root: str | Path) -> list[Path]:
    """Removes the local Ray temp folders under `root` whose driver is gone (killed before its
    shutdown removed them: Ray's own processes exit within about two minutes of the driver, the
    folder stays); the removed folders. A folder without a driver file, or whose driver is
    alive, is kept."""
    removed = []
    for d in Path(root).glob(RAY_TEMP_PREFIX + "*"):
        try:
            pid = int((d / RAY_DRIVER_FILE).read_text().strip())
        except (OSError, ValueError):
            continue
        if not _alive(pid):
            shutil.rmtree(d, ignore_errors=True)
            removed.append(d)
    return removed


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process
        return True
    return True


class RayExecutor(Executor):
    """Jobs as Ray tasks on a cluster (`address`: host:port, ray://host:port or "auto") or on a
    local Ray instance started for the sweep (None or "local"; None means RAY_ADDRESS if it is
    set), in a temp folder
    of its own and shut down when the jobs are done.

    The address is checked when the executor is made: its form, then that something answers there
    (within RAY_CONNECT_TIMEOUT_S), so a wrong one is a clear error before any work.
    """

    def __init__(self, address: str | None = None, *, max_in_flight: int | None = None):
        try:
            import ray  # optional (the `ray` extra)
        except ImportError:
            raise TgDrakeError(
                "the Ray executor needs Ray, which is not installed: "
                "pip install 'tg_drake[ray]'") from None
        if max_in_flight is not None and (not isinstance(max_in_flight, int)
                                          or max_in_flight < 1):
            raise TgDrakeError(f"workers (--workers) with the ray executor is the number of jobs "
                               f"in flight, ≥ 1; got {max_in_flight!r}")
        self._ray = ray
        if address is None and os.environ.get("RAY_ADDRESS"):
            address = os.environ["RAY_ADDRESS"]
        address = None if address == "local" else address
        self.address = address
        if address is not None and not ray.is_initialized():
            check_ray_address(address)
        self.max_in_flight = max_in_flight or 1000  # tasks submitted and not yet finished

    def _init(self) -> str | None:
        """Connects to the cluster or starts a local instance; the temp folder to remove after
        shutdown (a local instance's), or None."""
        ray = self._ray
        if self.address is not None:
            try:
                ray.init(address=self.address)
            except (ConnectionError, RuntimeError, ValueError, TimeoutError) as e:
                raise TgDrakeError(f"cannot connect to the Ray cluster at {self.address!r}: "
                                   f"{_quote(e)}") from None
            return None
        # A local instance of its own: a stale shared /tmp/ray (a crashed earlier instance) is
        # neither joined nor reused. The folder is short: Ray's sockets live under it, and a Unix
        # socket's path has at most 107 bytes.
        base = tempfile.gettempdir()
        root = base if len(base) <= 20 else "/tmp"
        remove_stale_ray_folders(root)
        temp_dir = tempfile.mkdtemp(prefix=RAY_TEMP_PREFIX, dir=root)
        Path(temp_dir, RAY_DRIVER_FILE).write_text(f"{os.getpid()}\n")
        ray.init(address="local", _temp_dir=temp_dir)
        return temp_dir

    def imap_unordered(self, fn, jobs):
        ray = self._ray
        started, temp_dir = False, None
        if not ray.is_initialized():
            temp_dir = self._init()
            started = True
        try:
            yield from self._imap(fn, jobs)
        finally:
            if started:
                ray.shutdown()
            if temp_dir is not None:
                shutil.rmtree(temp_dir, ignore_errors=True)

    def _imap(self, fn, jobs):
        ray = self._ray
        remote = ray.remote(max_retries=0)(call_job)  # retried here, and counted
        fn_ref = ray.put(fn)
        pending = deque(jobs)
        in_flight: dict = {}
        attempts: dict[str, int] = {}
        while pending or in_flight:
            while pending and len(in_flight) < self.max_in_flight:
                job = pending.popleft()
                attempts[job.key] = attempts.get(job.key, 0) + 1
                in_flight[remote.remote(fn_ref, job.payload, True)] = job
            (ready,), _ = ray.wait(list(in_flight), num_returns=1)
            job = in_flight.pop(ready)
            try:
                outcome = ray.get(ready)
            except ray.exceptions.RayTaskError as e:  # outside call_job: the job could not start
                cause = getattr(e, "cause", None) or e
                outcome = Outcome(None, f"the job could not run in a Ray worker: "
                                        f"{type(cause).__name__}: {_quote(cause)}")
            except ray.exceptions.RayError as e:  # the worker or its node died
                if attempts[job.key] < RAY_ATTEMPTS:
                    pending.appendleft(job)
                    continue
                outcome = Outcome(None, f"{WORKER_DIED}: {type(e).__name__}")
            yield job, dataclasses.replace(outcome, attempts=attempts[job.key])


def _quote(value: object) -> str:
    text = " ".join(str(value).split())
    return text if len(text) <= MAX_QUOTED else text[:MAX_QUOTED] + "…"


def parse_ray_address(address: str) -> tuple[str, int]:
    """(host, port) of a Ray address "host:port" or "ray://host:port" ("[::1]:6379" for IPv6);
    a TgDrakeError for anything else."""
    bad = TgDrakeError(f"malformed Ray address {_quote(address)!r}: expected host:port (e.g. "
                       "127.0.0.1:6379, the head node's GCS port), ray://host:port (Ray Client) "
                       "or auto (the cluster started on this machine with `ray start --head`)")
    rest = address.removeprefix("ray://")
    host, sep, port = rest.rpartition(":")
    if host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536 \
            or any(c in host for c in "/ @?#[]"):
        raise bad
    return host, int(port)


def resolve_ray_auto() -> str:
    """The address `ray.init(address="auto")` would connect to, found as Ray finds it
    (RAY_ADDRESS, the last cluster `ray start` recorded, a GCS process on this machine)."""
    try:
        from ray._private.services import canonicalize_bootstrap_address
    except ImportError:  # Ray moved its private helper: let ray.init resolve "auto" itself
        return "auto"
    try:
        found = canonicalize_bootstrap_address("auto")
    except (ConnectionError, ValueError) as e:
        raise TgDrakeError(f"--address auto: no Ray cluster found on this machine ({_quote(e)}); "
                           "start one with `ray start --head`, give its host:port, or leave "
                           "--address out to start a local Ray instance") from None
    return found or "auto"


def check_ray_address(address: str) -> None:
    """Raises a TgDrakeError unless `address` is well formed and something answers there."""
    where = address
    if address == "auto":
        resolved = resolve_ray_auto()
        if resolved == "auto":
            return
        where, address = f"auto ({resolved})", resolved
    host, port = parse_ray_address(address)
    try:
        if address.startswith("ray://"):  # a Ray Client server: a connection is all we check
            socket.create_connection((host, port), timeout=RAY_CONNECT_TIMEOUT_S).close()
            reason = None
        else:
            reason = _not_a_gcs(host, port)
    except OSError as e:
        reason = NO_ANSWER if isinstance(e, TimeoutError) else (e.strerror or str(e))
    if reason is not None:
        raise TgDrakeError(f"no Ray cluster at --address {where}: {reason} (is the cluster up? "
                           "`ray status` on the head node)") from None


def _frame(kind: int, flags: int, stream: int, payload: bytes = b"") -> bytes:
    """An HTTP/2 frame (RFC 9113, section 4.1)."""
    return (len(payload).to_bytes(3, "big") + bytes([kind, flags]) + stream.to_bytes(4, "big")
            + payload)


def _not_a_gcs(host: str, port: int) -> str | None:
    """None if a Ray GCS answers at host:port, else why not. Sends the GCS one gRPC call
    (GetClusterId, an empty request) over plain HTTP/2 and reads the status of its response: a
    GCS answers 200; a proxy or another server that accepts any connection answers otherwise."""

    def literal(name_index: int, value: str) -> bytes:  # HPACK, without indexing, no Huffman
        return bytes([name_index, len(value)]) + value.encode()

    headers = (b"\x83\x86"  # :method POST, :scheme http (HPACK static table)
               + literal(0x04, "/ray.rpc.NodeInfoGcsService/GetClusterId")  # :path
               + literal(0x01, f"{host}:{port}")  # :authority
               + b"\x0f\x10" + literal(0x10, "application/grpc")[1:]  # content-type
               + b"\x00" + literal(2, "te")[1:] + literal(8, "trailers")[1:])
    with socket.create_connection((host, port), timeout=RAY_CONNECT_TIMEOUT_S) as s:
        s.settimeout(RAY_CONNECT_TIMEOUT_S)
        s.sendall(b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n" + _frame(4, 0, 0)  # preface, SETTINGS
                  + _frame(1, 4, 1, headers)  # HEADERS, END_HEADERS
                  + _frame(0, 1, 1, bytes(5)))  # DATA, END_STREAM: an empty gRPC message
        deadline = time.monotonic() + RAY_CONNECT_TIMEOUT_S
        data = b""
        while time.monotonic() < deadline:
            while len(data) >= 9 and len(data) >= 9 + int.from_bytes(data[:3], "big"):
                n, kind, flags = int.from_bytes(data[:3], "big"), data[3], data[4]
                payload, data = data[9:9 + n], data[9 + n:]
                if kind == 4 and not flags & 1:  # the server's SETTINGS: acknowledge them
                    s.sendall(_frame(4, 1, 0))
                elif kind == 1:  # the response's HEADERS: ":status: 200" is 0x88 in HPACK
                    return None if payload[:1] == b"\x88" else "it answers, but not as a Ray GCS"
                elif kind in (3, 7):  # RST_STREAM, GOAWAY
                    return "it refused a Ray GCS request"
            chunk = s.recv(4096)
            if not chunk:
                return "it closed the connection (not a Ray GCS)"
            data += chunk
    return NO_ANSWER


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


def read_records(out: Path) -> list[dict]:
    """Every record in the results file `out` ([] if there is none). A torn last line (no newline
    at its end, not JSON: a run killed mid-write) is left out; any other line that is not a JSON
    object with a "job" key, a folder in place of the file, or a file that is not UTF-8 is an
    OutputError naming the file and the line."""
    return _read(out)[0]


def _read(out: Path) -> tuple[list[dict], int | None]:
    """The records of `out`, and the offset where a torn last line starts (None if none)."""
    if out.is_dir():
        raise OutputError("the results file is a folder", file=str(out))
    try:
        data = out.read_bytes()
    except FileNotFoundError:
        return [], None
    except OSError as e:
        raise OutputError(f"the results file cannot be read: {e.strerror}", file=str(out)) from None
    records, offset, torn = [], 0, None
    for number, line in enumerate(data.splitlines(keepends=True), start=1):
        start, offset = offset, offset + len(line)
        last = offset == len(data) and not line.endswith(b"\n")
        try:
            text = line.decode("utf-8")
        except UnicodeDecodeError as e:
            if last:
                torn = start
                break
            raise OutputError(f"not UTF-8 text (byte {e.start + 1} of the line): not a results "
                              "file of a sweep?", file=str(out), line=number) from None
        text = text.rstrip("\r\n")
        if not text.strip():
            continue
        try:
            record = json.loads(text)
        except json.JSONDecodeError as e:
            if last:
                torn = start
                break
            raise OutputError(f"not a JSON record ({e.msg}): {_quote(text)!r}; remove the line or "
                              "choose another output", file=str(out), line=number) from None
        if not isinstance(record, dict) or not isinstance(record.get("job"), str):
            raise OutputError('not a record of a sweep (expected a JSON object with a "job" '
                              f"string): {_quote(text)!r}", file=str(out), line=number)
        records.append(record)
    return records, torn


def finished_jobs(out: Path, *, retry_errors: bool = False) -> set[str]:
    """Keys of the jobs that already have a record in `out` (read_records)."""
    return {r["job"] for r in read_records(out)
            if not (retry_errors and r.get("status") == "error")}


def run_jobs(fn: Callable[[Any], Any], jobs: Iterable[Job], *, out: Path, executor: Executor,
             retry_errors: bool = False, progress: bool = True,
             outcome_of: Callable[[list[dict]], str] | None = None,
             label: str | None = None) -> RunSummary:
    """Runs the jobs not yet in `out` and appends their records to it as they finish.

    `label` names the work on the progress bar (default: the results file's name).

    `fn` must be importable by name (a module-level function) for process and Ray executors.
    `outcome_of(records)` names a finished job's outcome for the progress bar's counts (default
    "done"; a job recorded as an error counts as "error").
    """
    jobs = list(jobs)
    keys = [job.key for job in jobs]
    if len(set(keys)) != len(keys):
        raise TgDrakeError("job keys must be unique")
    check_output_file(out, what="results file")
    records, torn = _read(out)
    done = {r["job"] for r in records if not (retry_errors and r.get("status") == "error")}
    todo = [job for job in jobs if job.key not in done]
    out.parent.mkdir(parents=True, exist_ok=True)
    if torn is not None:  # the last line of a run killed mid-write: cut it off
        with out.open("r+b") as f:
            f.truncate(torn)
    summary = RunSummary(len(jobs), len(jobs) - len(todo), 0, 0, 0)
    bar = None
    if progress:
        from tqdm import tqdm  # start-up: this module is on `tg-drake --help`'s path; tqdm ~0.5 s

        # smoothing 0: the ETA from the mean time per job so far (jobs differ tenfold in cost).
        bar = tqdm(total=len(todo), desc=label or out.name, unit="job", bar_format=BAR_FORMAT,
                   smoothing=0.0)
    counts: dict[str, int] = {}
    shown: set[str] = set()  # log lines already printed above the bar
    with out.open("a") as f:
        # A last record without its newline (an edited file): start on a fresh line.
        if f.tell() > 0:
            with out.open("rb") as r:
                r.seek(-1, os.SEEK_END)
                if r.read(1) != b"\n":
                    f.write("\n")
        for job, outcome in executor.imap_unordered(fn, todo):
            if outcome.error is not None:
                records = [{"status": "error", "reason": outcome.error}]
                summary.n_errors += 1
                label = "error"
            else:
                records = outcome.records
                label = outcome_of(records) if outcome_of is not None else "done"
            where = {k: v for k, v in (("worker_pid", outcome.worker_pid),
                                       ("rss_mb", outcome.rss_mb),
                                       ("wall_s", outcome.wall_s)) if v is not None}
            if outcome.log:
                where["log"] = list(outcome.log)
            if outcome.attempts > 1:
                where["attempts"] = outcome.attempts
            records = [{**r, **where} for r in records]
            # One write per job: its lines land together.
            f.write("".join(json.dumps({"job": job.key, **r}) + "\n" for r in records))
            f.flush()
            summary.n_ran += 1
            summary.n_records += len(records)
            counts[label] = counts.get(label, 0) + 1
            if bar is not None:
                for line in outcome.log:
                    if line not in shown:  # each distinct line once, above the bar
                        shown.add(line)
                        bar.write(f"{job.key}: {line}", file=sys.stderr)
                bar.set_postfix_str(" ".join(f"{k}={v}" for k, v in counts.items()),
                                    refresh=False)
                bar.update(1)
                if bar.n == bar.total:  # its rate and time as the last job finished
                    bar.close()
    if bar is not None:
        bar.close()
    summary.counts = counts
    return summary
