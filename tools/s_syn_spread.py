"""S_SYN's category accuracy over many samplings: how much of a change in the table is the dice.

    python tools/s_syn_spread.py                       # 12 samplings → docs/results/s_syn_spread.*
    python tools/s_syn_spread.py --samplings 4 --out /tmp/spread
    python tools/s_syn_spread.py --database /tmp/kernel_db.npz --out /tmp/spread_other

S_SYN (scenarios/suites/s_syn.yaml) follows the paper: the kernel prior of each object comes from
ONE labelled sampling of its mesh (uniform points, a random rotation), drawn from the case's seed.
With 44 objects, one object whose sampling lands near another category's graphs moves the
Manifolds column by 2.3 points and the PLM column by its 2–4 cases (up to 3.2 points). This tool
runs the suite's cases (`tg_drake.evaluation.jobs.run_synthetic`, in this process) once per
sampling — the cases' seeds shifted by 0, 1, …, N − 1 — and measures each pass with the tables'
own rules (`tg_drake.evaluation.tables.category`: argmax, ties and impossible observations fail;
Manifolds over objects, the logic over cases), then reports each method's mean, standard
deviation and range, and the PLM's per category. Sampling 0 is the suite as `tg-drake eval` runs
it (its row equals tables.md's S_SYN row).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import shlex
import sys
import time
from pathlib import Path

import numpy as np

from tg_drake.evaluation import jobs
from tg_drake.evaluation.suite import load_suite
from tg_drake.evaluation.tables import LOGIC_METHODS, category, per_category

ROOT = Path(__file__).resolve().parents[1]
SUITE = ROOT / "scenarios" / "suites" / "s_syn.yaml"
OUT = ROOT / "docs" / "results" / "s_syn_spread"
METHODS = ("manifolds", *LOGIC_METHODS)


def sampling_records(cases, shift: int) -> list[dict]:
    """The suite's records with every case's seed shifted by `shift` (a new sampling of each
    object; nothing else in a synthetic case is random)."""
    return [jobs.run_synthetic(dataclasses.replace(c, seed=c.seed + shift)) for c in cases]


def spread(cases, n: int, progress=print) -> dict:
    """Per sampling, the tables' S_SYN category accuracies; then mean, sd, min and max."""
    rows, per_cat = [], []
    t0 = time.perf_counter()
    for k in range(n):
        records = sampling_records(cases, k)
        table = category(records)["syn"]
        rows.append({m: table[m] for m in METHODS})
        per_cat.append({c: v["plm"] for c, v in per_category(records)["syn"].items()})
        progress(f"  sampling {k + 1}/{n}: " + ", ".join(f"{m} {table[m]:.2f}" for m in METHODS)
                 + f" ({time.perf_counter() - t0:.0f} s)")
    summary = {}
    for m in METHODS:
        v = np.array([r[m] for r in rows])
        summary[m] = {"mean": round(float(v.mean()), 2), "sd": round(float(v.std(ddof=1)), 2)
                      if n > 1 else 0.0, "min": float(v.min()), "max": float(v.max())}
    cats = {c: round(float(np.mean([p[c] for p in per_cat])), 1) for c in per_cat[0]}
    return {"samplings": rows, "summary": summary, "plm_per_category_mean": cats,
            "n_cases": len(cases), "n_objects": len({c.target_placement.id for c in cases})}


def markdown(result: dict, command: str, database: str) -> str:
    n = len(result["samplings"])
    L = ["# S_SYN category accuracy over samplings", "",
         f"Command: `{command}`", "",
         f"S_SYN ({result['n_objects']} objects, {result['n_cases']} cases) takes each object's "
         "kernel prior from one labelled sampling of its mesh, as the paper does; this page runs "
         f"the suite {n} times, each case's seed shifted by 0..{n - 1} (a new sampling per "
         "object, nothing else changes), measured by the tables' rules (argmax; ties and "
         "impossible observations fail; Manifolds over objects, the logic over cases). Sampling "
         f"0 is the suite as `tg-drake eval` runs it. Kernel database: {database}.", "",
         "| method | mean | sd | min | max | sampling 0 |", "|---|---|---|---|---|---|"]
    for m in METHODS:
        s = result["summary"][m]
        L.append(f"| {m} | **{s['mean']:.2f}** | {s['sd']:.2f} | {s['min']:.2f} | "
                 f"{s['max']:.2f} | {result['samplings'][0][m]:.2f} |")
    L += ["", "PLM per category, mean over the samplings: " + ", ".join(
        f"{c} {v:.1f}" for c, v in result["plm_per_category_mean"].items()) + ".", "",
        "Per sampling:", "", "| sampling | " + " | ".join(METHODS) + " |",
        "|---|" + "---|" * len(METHODS)]
    for k, r in enumerate(result["samplings"]):
        L.append(f"| {k} | " + " | ".join(f"{r[m]:.2f}" for m in METHODS) + " |")
    return "\n".join(L) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samplings", type=int, default=12, help="samplings (default 12)")
    parser.add_argument("--database", default=None,
                        help="a kernel database file (default: the shipped one)")
    parser.add_argument("--out", type=Path, default=OUT,
                        help="file stem of the .md and .json (default docs/results/s_syn_spread)")
    args = parser.parse_args(argv)
    if args.samplings < 1:
        parser.error("--samplings must be >= 1")
    database = "the shipped tg_drake/data/kernel_db.npz"
    if args.database is not None:
        if not Path(args.database).is_file():
            parser.error(f"--database {args.database}: no such file")
        jobs.use_database(args.database)  # every prior and floor from that file
        database = args.database
    _, cases = load_suite(SUITE)
    result = spread(cases, args.samplings)
    command = "python tools/s_syn_spread.py " + " ".join(
        shlex.quote(a) for a in (sys.argv[1:] if argv is None else argv))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.with_suffix(".json").write_text(json.dumps(
        {"command": command.strip(), "database": database, **result}, indent=1) + "\n")
    page = markdown(result, command.strip(), database)
    args.out.with_suffix(".md").write_text(page)
    print(page)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
