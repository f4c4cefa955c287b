"""Speed figures of the evaluation: `sweep_efficiency`, `suite_case_s`, `worker_rss_mb`, and
`perception_ms` (the perception stage's time per object beside the paper's published one).

- `sweep_efficiency`: a small evaluation sweep — the first 64 cases of the S_REAL suite (render,
  perceive, kernel prior, every logic method; about 0.3–2 s each) — run by the local process pool
  with 2 workers, against the same sweep with 1 worker. Each run starts a fresh pool and writes its
  own results file, so the time includes spawning the workers, as a user's sweep does; the
  compiled theories are on disk before either run (tg_drake.logic.cache: a user's machine compiles
  them once). speedup = time with 1 worker / time with 2 workers: 2 is perfect scaling.
- `suite_case_s`: a fixed 12-case subset of S_GRASP (every 11th case of the suite: several
  objects, poses and tasks) run as one sweep by one warm worker, against the same cases each run
  as a separate `tg-drake run` process (start-up, imports, loading, building every time).
- `worker_rss_mb`: the peak resident memory of that sweep's worker (its records' `rss_mb`).
"""

from __future__ import annotations

import functools
import statistics
import subprocess
import sys
import tempfile
import time
from importlib.resources import files
from pathlib import Path

import numpy as np
from pydrake.common.yaml import yaml_dump_typed

from tg_drake.bench import Figure, figure
from tg_drake.evaluation.cli import _ordered, _run
from tg_drake.evaluation.jobs import METHODS, scenario_of
from tg_drake.evaluation.paper import PAPER
from tg_drake.evaluation.suite import load_suite
from tg_drake.executor import Job, LocalExecutor, read_records, run_jobs
from tg_drake.logic.engine import compiled_theory
from tg_drake.logic.theory import TheoryConfig
from tg_drake.perception.bench import object_times_ms

N_CASES = 64
SUITE_STRIDE = 11  # suite_case_s: every 11th case of S_GRASP's 132
N_SUITE_CASES = 12


def _suites() -> Path:
    return Path(str(files("tg_drake"))).parent / "scenarios" / "suites"


def _compile_theories() -> None:
    """Every theory variant the evaluation's logic methods use, compiled (onto disk) now."""
    for cat, grasp, _, *_ in METHODS.values():
        for models in (cat, grasp):
            compiled_theory(TheoryConfig(category=models[0], grasp=models[1],
                                         exclusive=models[2]))


def _sweep_seconds(cases, workers: int) -> float:
    with tempfile.TemporaryDirectory() as folder:
        t0 = time.perf_counter()
        run_jobs(_run, [Job(c.key, c) for c in cases], out=Path(folder) / "results.jsonl",
                 executor=LocalExecutor(workers), progress=False)
        return time.perf_counter() - t0


def sweep_efficiency() -> Figure:
    """Seconds for the sweep with 2 workers (one run; reference: one run with 1 worker)."""
    cases = load_suite(_suites() / "s_real.yaml")[1][:N_CASES]
    _compile_theories()
    one = _sweep_seconds(cases, 1)
    two = _sweep_seconds(cases, 2)
    return figure(two, "s", f"the same sweep of {N_CASES} S_REAL cases with 1 worker (a fresh "
                  "local pool each; speed-up 2 = perfect scaling over 2 workers)", one)


def perception_ms() -> Figure:
    """Median time to describe one object (completion + pose + parts) [ms], beside the paper's
    completion + pose detection per object (published on one core of a 2.67 GHz Xeon, not re-run
    here)."""
    times = object_times_ms()
    paper = PAPER["detection_ms"]
    reference = paper["completion"] + paper["pose"]
    return figure(float(np.median(times)), "ms",
                  f"paper: {paper['completion']:g} ms completion + {paper['pose']:g} ms pose per "
                  f"object on one core of a 2.67 GHz Xeon (published figure, not re-run); ours: "
                  f"median over {len(times)} objects of a ray-cast scene", reference)


def suite_cases() -> list:
    """The fixed S_GRASP subset of suite_case_s, in a sweep's order (grouped by object)."""
    return _ordered(load_suite(_suites() / "s_grasp.yaml")[1][::SUITE_STRIDE][:N_SUITE_CASES])


@functools.cache
def _suite_sweep() -> tuple[list[dict], float]:
    """The records of the subset run as one sweep by one worker, and its wall time [s]."""
    cases = suite_cases()
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "results.jsonl"
        t0 = time.perf_counter()
        run_jobs(_run, [Job(c.key, c) for c in cases], out=out, executor=LocalExecutor(1),
                 progress=False)
        return read_records(out), time.perf_counter() - t0


def _separate_run_seconds(case, folder: Path) -> float:
    """Wall seconds of `tg-drake run` on the case's scenario in a process of its own."""
    path = folder / (case.key.replace("/", "_").replace("&", "") + ".yaml")
    path.write_text(yaml_dump_typed(scenario_of(case)))
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "tg_drake.cli", "run", str(path), "--out",
                    str(folder / path.stem), "--no-images"], check=False,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


def suite_case_s() -> Figure:
    """Median wall seconds per executed case of the S_GRASP subset run as one sweep (one warm
    worker; each record's `wall_s`), against the median of the same cases each run as a separate
    `tg-drake run` process."""
    records, _ = _suite_sweep()
    sweep = statistics.median(r["wall_s"] for r in records)
    with tempfile.TemporaryDirectory() as folder:
        separate = statistics.median(_separate_run_seconds(c, Path(folder))
                                     for c in suite_cases())
    return figure(sweep, "s / case", f"the same {N_SUITE_CASES} S_GRASP cases (every "
                  f"{SUITE_STRIDE}th of the suite), each a separate `tg-drake run --no-images` "
                  "process", separate)


def worker_rss_mb() -> Figure:
    """Peak resident memory of the suite_case_s sweep's worker [MB] (issue 22's goal: 1,500 MB;
    no reference)."""
    records, _ = _suite_sweep()
    return figure(max(r["rss_mb"] for r in records), "MB",
                  f"peak RSS of the one worker of a {N_SUITE_CASES}-case S_GRASP sweep (ru_maxrss;"
                  " no reference)")
