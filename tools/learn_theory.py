"""Learns the theory's grasp and category probabilities from simulated grasp outcomes (issue 9).

    python tools/learn_theory.py                       # collect, fit, write rules/*_learned.pl,
                                                       # compare on held-out objects
    python tools/learn_theory.py --stage collect       # only run the data collection
    python tools/learn_theory.py --stage fit           # fit from collected data, write the theory
    python tools/learn_theory.py --stage compare       # held-out comparison -> docs/results/
    options: --seed 0 --workers 1 --executor local|ray --address ADDR --max-iter 50

Data. Every library object, in every pose that suits it, empty, and full when upright (containers
only), grasped in turn at each of its parts: the pipeline runs with ground-truth perception (the
paper's S_SYN setting), the task p&pOn (every object affords it; the task does not change what
the robot does once the part is fixed) and `PipelineConfig.grasp_part` set, so that only that
part's pre-grasp hypotheses are tried, best P(grasp | shape) first. A position and yaw on the table
are drawn per scene from the seed. Upside-down pans are left out: the theory's constraint rules
every grasp of them out, so nothing would be executed. One object per category (drawn from the
seed) is held out for the comparison; the others are the training objects. Records stream to
data/learning/grasps.jsonl (resumable).

Fit (tg_drake.logic.learning). A record is executed when the robot closed the gripper on the
chosen part; it then says, for every task the scene affords, whether grasping that part served
the task: held through lift and place AND the part is one the task allows
(`learning.allowed_parts`, a table written from what each task needs, not from the theory).
Those become ProbLog interpretations; ProbLog's learning from interpretations fits the grasp
model's probabilities (from the training objects' records) and, separately, the category model's
(from the training objects' labelled parts and poses), starting from the hand-written values. The
learned models are written as rules/grasp_learned.pl and rules/category_learned.pl; the theory
variant "learned" uses both (`--theory learned`).

Compare. On the held-out objects: pre-grasp E_0 accuracy (the theory's top part, ties included,
must be among the parts whose grasp served the task in the held-out data) for every held-out
scene and task with at least one such part, and grasp success through the whole pipeline (one
task per held-out scene, drawn from the seed; the theory picks the part) with either theory.
Writes docs/results/learning.json and .md; a data summary to docs/results/learning_data.json.
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
from collections import Counter
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "docs" / "results"
DATA = ROOT / "data" / "learning"
RUN_TASK = "p&pOn"  # the task the collection runs ask for: every object affords it.
PLACE_XY = [0.0, -0.3]  # table frame, as tools/eval_pipeline.py


# ---- data collection ---------------------------------------------------------------------------

def split_objects(seed: int) -> dict[str, str]:
    """Object id -> "train" or "test": one object per category held out, drawn from the seed."""
    from tg_drake.objects import library_by_category

    rng = np.random.default_rng(seed)
    split = {}
    for category, objects in library_by_category().items():
        held_out = int(rng.integers(len(objects)))
        for i, obj in enumerate(objects):
            split[obj.id] = "test" if i == held_out else "train"
    return split


def scenes(seed: int) -> list[dict]:
    """Every (object, pose, containment) scene of the collection, with its position and yaw."""
    from tg_drake.objects import load_library

    rng = np.random.default_rng(seed + 1)
    split = split_objects(seed)
    out = []
    for obj in load_library().values():
        for pose in obj.poses:
            if obj.category == "pan" and pose == "upsidedown":
                continue  # the theory's constraint: an upside-down pan is not grasped.
            fillings = ["empty"]
            if obj.cavity_volume is not None and pose == "upright":
                fillings.append("full")
            for containment in fillings:
                xy = [round(float(rng.uniform(-0.08, 0.08)), 3),
                      round(float(rng.uniform(-0.12, 0.12)), 3)]
                out.append({"scene": f"{obj.id}_{pose}_{containment}", "id": obj.id,
                            "category": obj.category, "pose": pose, "containment": containment,
                            "parts": list(obj.parts), "xy": xy,
                            "yaw": round(float(rng.uniform(0.0, 360.0)), 1),
                            "split": split[obj.id]})
    return out


def collection_specs(seed: int) -> list[dict]:
    """One spec per scene and part: the held-out objects' first (the comparison needs every
    part of them), then the training objects' in a seeded order (a cut-short run still covers
    every kind of object)."""
    specs = [{**s, "part": part, "name": f"{s['scene']}_{part}"}
             for s in scenes(seed) for part in s["parts"]]
    order = np.random.default_rng(seed + 2).permutation(len(specs))
    return sorted((specs[i] for i in order), key=lambda s: s["split"] != "test")


def _scenario(spec: dict, *, task: str, grasp_part: str | None = None, theory: str = "specific"):
    from tg_drake.scenario import (
        ObjectPlacement,
        PipelineConfig,
        Scenario,
        TaskConfig,
        validate,
    )

    scenario = Scenario(
        objects=[ObjectPlacement(id=spec["id"], pose=spec["pose"], xy=spec["xy"],
                                 yaw=spec["yaw"], containment=spec["containment"])],
        task=TaskConfig(task=task, place_xy=PLACE_XY),
        pipeline=PipelineConfig(perception="ground_truth", grasp_part=grasp_part,
                                category_theory=theory, grasp_theory=theory,
                                min_grasp_probability=0.0 if grasp_part else 0.03))
    validate(scenario, where=spec["name"])
    return scenario


def _record(spec: dict, result: dict) -> dict:
    return {**spec, "outcome": result["outcome"],
            "grasped_part": (result.get("grasp") or {}).get("part"),
            "perception": result.get("perception"),
            "category_prior": result.get("category_prior"),
            "logic_part": result.get("part"), "logic_category": result.get("category"),
            "timings": result.get("timings")}


def collect_one(spec: dict) -> dict:
    """Runs one collection spec: the pipeline grasps `spec["part"]`."""
    from tg_drake.run import run_scenario

    scenario = _scenario(spec, task=RUN_TASK, grasp_part=spec["part"])
    return _record(spec, run_scenario(scenario, scenario_path=spec["name"]))


def compare_one(spec: dict) -> dict:
    """Runs one held-out scene through the whole pipeline with `spec["theory"]` choosing."""
    from tg_drake.run import run_scenario

    scenario = _scenario(spec, task=spec["task"], theory=spec["theory"])
    return _record(spec, run_scenario(scenario, scenario_path=spec["name"]))


def _run(fn, specs: list[dict], out: Path, args) -> list[dict]:
    from tg_drake.executor import Job, make_executor, run_jobs

    out.parent.mkdir(parents=True, exist_ok=True)
    executor = make_executor(args.executor, workers=args.workers, address=args.address)
    run_jobs(fn, [Job(s["name"], s) for s in specs], out=out, executor=executor)
    return _read(out, specs)


def _read(out: Path, specs: list[dict]) -> list[dict]:
    by_name = {s["name"]: s for s in specs}
    records = []
    if not out.is_file():
        return records
    for line in out.read_text().splitlines():
        if not line.strip():
            continue
        r = json.loads(line)
        if r.get("job") not in by_name:
            continue
        if "outcome" not in r:  # the job raised: keep its spec, mark it not executed.
            r = {**by_name[r["job"]], "outcome": {"status": "failed", "reason": "error",
                                                 "detail": r.get("reason", "")}}
        records.append(r)
    return records


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stage", choices=("all", "collect", "fit", "compare"), default="all")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--executor", choices=("local", "ray"), default="local")
    parser.add_argument("--address", default=None, help="Ray cluster address")
    parser.add_argument("--data", type=Path, default=DATA, help="where the raw records go")
    parser.add_argument("--max-iter", type=int, default=50, help="EM iterations of the fit")
    args = parser.parse_args(argv)
    command = "python tools/learn_theory.py " + shlex.join(argv if argv is not None
                                                           else sys.argv[1:])

    specs = collection_specs(args.seed)
    if args.stage in ("all", "collect"):
        records = _run(collect_one, specs, args.data / "grasps.jsonl", args)
        status = Counter(r["outcome"]["status"] for r in records)
        print(f"collected {len(records)} of {len(specs)} grasps: {dict(status)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
