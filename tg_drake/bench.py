"""`tg-drake bench`: speed figures, each a ratio against a reference measured in the same run.

Each figure is a function returning a `Figure`; stages register theirs in FIGURES
(name → "module:function").
Output: one JSON object, figure name → {median, unit, reference, reference_median, speedup}, and
"_run": where and how it was measured (the command, commit, date, cores, load average at the start,
package versions, wall time), since every figure is of one machine on one day.
"""

from __future__ import annotations

import datetime
import importlib
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

HELP = "measure the speed figures (JSON of medians and ratios against references)"

# figure name → "module:function" returning a Figure. Order is the output order.
FIGURES: dict[str, str] = {
    "sim_rtf": "tg_drake.simulation.scripted:bench_sim_rtf",
    "kernel_query_ms": "tg_drake.kernels.bench:kernel_query_ms",
    "kernel_loo_s": "tg_drake.kernels.bench:kernel_loo_s",
    "logic_scene_ms": "tg_drake.logic.bench:logic_scene_ms",
    "perception_ms": "tg_drake.evaluation.bench:perception_ms",
    "segmentation_ms": "tg_drake.perception.bench:segmentation_ms",
    "dgi_us_per_hypothesis": "tg_drake.grasping.bench:dgi_us_per_hypothesis",
    "sweep_efficiency": "tg_drake.evaluation.bench:sweep_efficiency",
    "suite_case_s": "tg_drake.evaluation.bench:suite_case_s",
    "worker_rss_mb": "tg_drake.evaluation.bench:worker_rss_mb",
    "pipeline_rtf": "tg_drake.run:bench_pipeline_rtf",
    "import_s": "tg_drake.importing.bench:import_s",
    "scan_run_ratio": "tg_drake.run:bench_scan_run_ratio",
    "pour_run_ratio": "tg_drake.simulation.pour:bench_pour_run_ratio",
}


@dataclass
class Figure:
    median: float
    unit: str
    reference: str | None = None  # what the reference is
    reference_median: float | None = None
    # > 1: we are faster (reference/median for times, median/reference for rates)
    speedup: float | None = None


def median_time(fn: Callable[[], object], *, repeats: int = 5, warmup: int = 1) -> float:
    """Median wall time of `fn()` over `repeats` calls, after `warmup` untimed calls [s]."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def figure(median: float, unit: str, reference: str | None = None,
           reference_median: float | None = None) -> Figure:
    speedup = (reference_median / median) if (reference_median and median) else None
    return Figure(median, unit, reference, reference_median, speedup)


def add_arguments(parser) -> None:
    parser.add_argument("--out", type=Path, help="write the JSON here (also printed)")
    parser.add_argument("--only", action="append", choices=sorted(FIGURES),
                        help="run only this figure (repeatable)")


def rounded(value, digits: int = 4):
    """Floats to `digits` significant digits, through dicts and lists (timings vary more)."""
    if isinstance(value, float):
        return float(f"{value:.{digits}g}")
    if isinstance(value, dict):
        return {k: rounded(v, digits) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [rounded(v, digits) for v in value]
    return value


def _commit() -> str | None:
    """The checkout's short commit, "+dirty" when tracked files changed; None outside git."""
    root = Path(__file__).resolve().parent.parent
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=root, text=True,
                              capture_output=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                               text=True, capture_output=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None
    return head + ("+dirty" if dirty else "")


def run_info(argv: list[str] | None = None) -> dict:
    """Where and how the figures were measured (stored beside them as "_run")."""
    from importlib.metadata import PackageNotFoundError, version
    versions = {}
    for name in ("drake", "numpy", "open3d", "problog", "scikit-learn"):
        try:
            versions[name] = version(name)
        except PackageNotFoundError:
            versions[name] = None
    return {
        "command": "tg-drake bench" + "".join(f" {a}" for a in (argv or [])),
        "commit": _commit(),
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "cpus": os.cpu_count(),
        "load_average_1min_at_start": round(os.getloadavg()[0], 2),
        "machine": f"{platform.system()} {platform.machine()}, Python {platform.python_version()}",
        "versions": versions,
    }


def main(args) -> int:
    names = args.only or list(FIGURES)
    argv = [f"--only {n}" for n in args.only or []] + ([f"--out {args.out}"] if args.out else [])
    info = run_info(argv)
    t0 = time.perf_counter()
    results = {}
    for name in names:
        module_name, function_name = FIGURES[name].split(":")
        fn = getattr(importlib.import_module(module_name), function_name)
        results[name] = rounded(asdict(fn()))
        print(f"{name}: {results[name]}", file=sys.stderr, flush=True)  # progress: stdout is JSON
    results["_run"] = {**info, "wall_s": round(time.perf_counter() - t0, 1)}
    text = json.dumps(results, indent=2)
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(text + "\n")
    print(text)
    return 0
