"""Speed figures of the evaluation: `sweep_efficiency`, and `perception_ms` (the perception stage's
time per object beside the paper's published one).

A small evaluation sweep — the first 64 cases of the S_REAL suite (render, perceive, kernel prior,
every logic method; about 0.3–2 s each) — run by the local process pool with 2 workers, against
the same sweep with 1 worker. Each run starts a fresh pool and writes its own results file, so the
time includes spawning the workers and compiling the theories in each, as a user's sweep does.
speedup = time with 1 worker / time with 2 workers: 2 is perfect scaling on this machine.
"""

from __future__ import annotations

import tempfile
import time
from importlib.resources import files
from pathlib import Path

import numpy as np

from tg_drake.bench import Figure, figure
from tg_drake.evaluation.cli import _run
from tg_drake.evaluation.paper import PAPER
from tg_drake.evaluation.suite import load_suite
from tg_drake.executor import Job, LocalExecutor, run_jobs
from tg_drake.perception.bench import object_times_ms

N_CASES = 64


def _sweep_seconds(cases, workers: int) -> float:
    with tempfile.TemporaryDirectory() as folder:
        t0 = time.perf_counter()
        run_jobs(_run, [Job(c.key, c) for c in cases], out=Path(folder) / "results.jsonl",
                 executor=LocalExecutor(workers), progress=False)
        return time.perf_counter() - t0


def sweep_efficiency() -> Figure:
    """Seconds for the sweep with 2 workers (one run; reference: one run with 1 worker)."""
    suite = Path(str(files("tg_drake"))).parent / "scenarios" / "suites" / "s_real.yaml"
    cases = load_suite(suite)[1][:N_CASES]
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
