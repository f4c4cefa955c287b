"""How repeatable are the physics labels of the DGI training set? The ceiling of any classifier.

Re-executes a random sample of the recorded grasps of tools/collect_grasps.py, stratified by
object category and label, with `tg_drake.grasping.episode` (the same world, object pose and
episode script as the collection):

- "exact": the same gripper pose again — does the simulation give the same label twice?
- "nudged" (`--nudges` of them per grasp): the gripper pose moved by `--nudge-mm` in a random
  direction and turned by `--nudge-deg` about a random axis through the grasp point (the pads'
  centre). No feature of local shape at the perception's 4 mm resolution can tell these poses
  apart, so how often their labels differ bounds what any classifier of it can reach.

If a grasp's label is a coin that lands "success" with probability p under such tiny changes,
the best any classifier can do on it is max(p, 1 − p), and two draws agree with probability
a = p² + (1 − p)². With ā the mean agreement of the original label with the nudged ones
(weighted to the data set's mix of categories and labels), the attainable accuracy lies between
ā and (1 + √(2ā − 1)) / 2 (Jensen: each grasp's max(p, 1 − p) = (1 + √(2a − 1)) / 2 is concave
in a). That interval is reported as the ceiling.

Jobs go through the executor interface (JSON Lines, resumable); the analysis is printed and, with
--results, merged into docs/results/dgi.json under "label_repeatability".

    nice -n 10 .venv/bin/python tools/label_noise.py --data data/dgi/grasps.jsonl \
        --out data/dgi/label_noise.jsonl --per-stratum 16 --nudges 2 --results docs/results/dgi.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import defaultdict
from dataclasses import asdict
from pathlib import Path

import numpy as np

from tg_drake.errors import GraspingError
from tg_drake.executor import EXECUTORS, Job, make_executor, run_jobs
from tg_drake.grasping.dgi import PAD_CENTER_Y
from tg_drake.grasping.episode import EpisodeConfig, run_grasp_batch
from tg_drake.objects import get_object


def category(object_id: str) -> str:
    return get_object(object_id).category


def stratified_sample(records: list[dict], per_stratum: int, rng: np.random.Generator
                      ) -> list[dict]:
    """Up to `per_stratum` random "ok" records of every (category, label)."""
    strata: dict[tuple[str, bool], list[dict]] = defaultdict(list)
    for r in records:
        if r.get("status") == "ok":
            strata[(category(r["object"]), bool(r["success"]))].append(r)
    sample = []
    for key in sorted(strata):
        rows = strata[key]
        pick = rng.choice(len(rows), size=min(per_stratum, len(rows)), replace=False)
        sample.extend(rows[i] for i in sorted(pick))
    return sample


def nudge(X_WG: np.ndarray, rng: np.random.Generator, *, distance: float, angle: float
          ) -> np.ndarray:
    """X_WG turned by `angle` [rad] about a random axis through its grasp point, which moves by
    `distance` [m] in a random direction."""
    from scipy.spatial.transform import Rotation

    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    shift = rng.normal(size=3)
    shift *= distance / np.linalg.norm(shift)
    R = Rotation.from_rotvec(angle * axis).as_matrix() @ X_WG[:3, :3]
    grasp_point = X_WG[:3, 3] + PAD_CENTER_Y * X_WG[:3, 1] + shift
    X = np.eye(4)
    X[:3, :3] = R
    X[:3, 3] = grasp_point - PAD_CENTER_Y * R[:, 1]
    return X


def make_jobs(sample: list[dict], *, nudges: int, distance: float, angle: float, seed: int,
              batch: int) -> list[Job]:
    """One batch of re-executions per scene: each sampled grasp exactly once, nudged `nudges`
    times."""
    rng = np.random.default_rng(seed)
    by_scene: dict[tuple[str, str], list[dict]] = defaultdict(list)
    for r in sample:
        by_scene[(r["object"], r["pose"])].append(r)
    jobs = []
    for (object_id, pose), rows in sorted(by_scene.items()):
        obj = get_object(object_id)
        X_WO = obj.resting_pose(pose).X_TO
        grasps = []
        for r in rows:
            X_WG = np.array(r["X_WG"], dtype=float).reshape(4, 4)
            base = {"source_job": r["job"], "source_index": r["index"], "kind": r["kind"],
                    "part": r["part"], "original_success": bool(r["success"])}
            grasps.append({**base, "index": len(grasps), "trial": "exact",
                           "X_WG": X_WG.ravel().tolist()})
            for k in range(nudges):
                X = nudge(X_WG, rng, distance=distance, angle=angle)
                grasps.append({**base, "index": len(grasps), "trial": f"nudge{k}",
                               "X_WG": X.ravel().tolist()})
        for b in range(0, len(grasps), batch):
            jobs.append(Job(f"{object_id}/{pose}/{b // batch}", {
                "object": object_id, "pose": pose, "object_sdf": str(obj.sdf_path),
                "X_WO": X_WO.ravel().tolist(), "config": asdict(EpisodeConfig()),
                "grasps": grasps[b:b + batch]}))
    return jobs


def _ceiling(agreement: float) -> list[float]:
    return [agreement, (1 + np.sqrt(max(2 * agreement - 1, 0.0))) / 2]


def stratum_weights(records: list[dict], sample: list[dict]) -> dict[tuple[str, int], float]:
    """(job, index) of each sampled grasp → its stratum's share of the data over its share of the
    sample, so that weighted means over the sample estimate means over the whole data set."""
    def stratum(r):
        return category(r["object"]), bool(r["success"])

    population = defaultdict(int)
    for r in records:
        if r.get("status") == "ok":
            population[stratum(r)] += 1
    sampled = defaultdict(int)
    for r in sample:
        sampled[stratum(r)] += 1
    return {(r["job"], r["index"]): population[stratum(r)] / sampled[stratum(r)] for r in sample}


def analyse(rows: list[dict], weights: dict[tuple[str, int], float] | None = None) -> dict:
    """Repeat rates of the labels (see the module docstring). With `weights` (per source grasp,
    `stratum_weights`) the headline rates and the ceiling are weighted to the data set's mix of
    categories and labels; the per-group rates are plain means over the sample."""
    ok = [r for r in rows if r.get("status") == "ok"]
    errors = [r for r in rows if r.get("status") != "ok"]
    by_grasp: dict[tuple[str, int], dict] = defaultdict(dict)
    for r in ok:
        by_grasp[(r["source_job"], r["source_index"])][r["trial"]] = r
    exact, nudged, all_agree, w_nudged = [], [], [], []
    groups: dict[str, dict[str, list]] = defaultdict(lambda: defaultdict(list))
    flips = []
    for trials in by_grasp.values():
        first = next(iter(trials.values()))
        original = first["original_success"]
        if "exact" in trials:
            exact.append(trials["exact"]["success"] == original)
        agree = [t["success"] == original for name, t in trials.items() if name != "exact"]
        nudged.extend(agree)
        w = weights.get((first["source_job"], first["source_index"]), 1.0) if weights else 1.0
        w_nudged.extend((w, a) for a in agree)
        if agree:
            all_agree.append(all(agree))
        for key in (f"kind/{first['kind']}", f"category/{category(first['object'])}",
                    f"label/{'positive' if original else 'negative'}"):
            groups[key]["nudged"].extend(agree)
        for name, t in trials.items():
            if t["success"] != original:
                flips.append({"trial": name, "original_success": original,
                              "finger_gap": t["finger_gap"], "object_rise": t["object_rise"],
                              "touches_table": t["touches_table"]})
    a = float(np.mean(nudged)) if nudged else float("nan")
    w_a = (float(np.average([a for _, a in w_nudged], weights=[w for w, _ in w_nudged]))
           if w_nudged else float("nan"))
    result = {
        "n_grasps": len(by_grasp),
        "n_episodes": len(rows),
        "n_sim_error": len(errors),
        "exact_repeat_rate": float(np.mean(exact)) if exact else None,
        "nudged_agreement_sample": a,
        "nudged_agreement": w_a,  # weighted to the data set's categories and labels
        "nudged_all_agree": float(np.mean(all_agree)) if all_agree else None,
        "accuracy_ceiling_interval": _ceiling(w_a),
        "by_group": {k: {"n": len(v["nudged"]), "nudged_agreement": float(np.mean(v["nudged"]))}
                     for k, v in sorted(groups.items()) if v["nudged"]},
    }
    # Why labels flip: a flip to failure that kept the object in the fingers but on the table
    # (lifted too little) is a different defect from one that lost it.
    reasons = defaultdict(int)
    for f in flips:
        if f["original_success"]:
            if f["touches_table"] and f["finger_gap"] > 0.002:
                reasons["to failure: still in the fingers, touching the table"] += 1
            else:
                reasons["to failure: fingers closed on nothing / lost it"] += 1
        else:
            reasons["to success"] += 1
    result["flips"] = dict(reasons)
    return result


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=Path("data/dgi/grasps.jsonl"))
    parser.add_argument("--out", type=Path, default=Path("data/dgi/label_noise.jsonl"))
    parser.add_argument("--per-stratum", type=int, default=16,
                        help="grasps per (category, label) stratum")
    parser.add_argument("--nudges", type=int, default=2, help="nudged re-executions per grasp")
    parser.add_argument("--nudge-mm", type=float, default=1.0)
    parser.add_argument("--nudge-deg", type=float, default=1.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--batch", type=int, default=30, help="episodes per job")
    parser.add_argument("--executor", choices=EXECUTORS, default="local")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--address", help="Ray cluster address (with --executor ray)")
    parser.add_argument("--results", type=Path,
                        help="merge the analysis into this JSON file (docs/results/dgi.json)")
    args = parser.parse_args(argv)

    if not args.data.is_file():
        raise GraspingError("no grasp records; collect them with tools/collect_grasps.py",
                        file=str(args.data))
    records = [json.loads(line) for line in args.data.read_text().splitlines() if line.strip()]
    sample = stratified_sample(records, args.per_stratum, np.random.default_rng(args.seed))
    jobs = make_jobs(sample, nudges=args.nudges, distance=args.nudge_mm / 1000,
                     angle=np.radians(args.nudge_deg), seed=args.seed, batch=args.batch)
    print(f"{len(sample)} grasps, {sum(len(j.payload['grasps']) for j in jobs)} episodes in "
          f"{len(jobs)} jobs", flush=True)
    start = time.perf_counter()
    run_jobs(run_grasp_batch, jobs, out=args.out,
             executor=make_executor(args.executor, workers=args.workers, address=args.address))
    keys = {j.key for j in jobs}
    rows = [json.loads(line) for line in args.out.read_text().splitlines() if line.strip()]
    result = analyse([r for r in rows if r["job"] in keys], stratum_weights(records, sample))
    result.update(per_stratum=args.per_stratum, nudges=args.nudges, nudge_mm=args.nudge_mm,
                  nudge_deg=args.nudge_deg, wall_seconds=time.perf_counter() - start,
                  command="nice -n 10 .venv/bin/python tools/label_noise.py " + " ".join(
                      sys.argv[1:] if argv is None else argv))
    print(json.dumps(result, indent=1))
    if args.results:
        existing = json.loads(args.results.read_text()) if args.results.is_file() else {}
        existing["label_repeatability"] = result
        args.results.write_text(json.dumps(existing, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
