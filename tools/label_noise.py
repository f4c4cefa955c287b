"""How repeatable are the physics labels of the DGI training set? The ceiling of any classifier.

Re-executes a random sample of the recorded grasps of tools/collect_grasps.py, stratified by
object category and label, with `tg_drake.simulation.episode` (the same world, object pose and
episode script as the collection):

- "exact": the same gripper pose again — does the simulation give the same label twice?
- "nudged" (`--nudges` of them per grasp): the gripper pose moved by `--nudge-mm` in a random
  direction and turned by `--nudge-deg` about a random axis through the grasp point (the pads'
  centre). These poses differ far less than the perception's 4 mm resolution, so how often
  their labels differ bounds what any classifier of local shape can reach.

The ceiling of any classifier on these labels follows from the agreement of the recorded label
with the nudged ones (`tg_drake.grasping.repeatability`).

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
from tg_drake.grasping.repeatability import (
    analyse,
    held,
    nudge,
    stratified_sample,
    stratum_weights,
)
from tg_drake.objects import get_object
from tg_drake.simulation.episode import EpisodeConfig, run_grasp_batch


def category(object_id: str) -> str:
    return get_object(object_id).category


def stratum(record: dict) -> tuple[str, bool]:
    """The sample's strata: object category and recorded label."""
    return category(record["object"]), bool(record["success"])


def groups(row: dict) -> list[str]:
    """The groups a re-executed grasp is reported in."""
    return [f"kind/{row['kind']}", f"category/{category(row['object'])}",
            f"label/{'positive' if row['original_success'] else 'negative'}"]


def episode_config(text: str | None) -> EpisodeConfig:
    """EpisodeConfig with the overrides "field=value,field=value" (floats)."""
    from dataclasses import fields

    from tg_drake.errors import unknown_name

    names = [f.name for f in fields(EpisodeConfig)]
    overrides = {}
    for item in filter(None, (text or "").split(",")):
        name, _, value = item.partition("=")
        if name not in names:
            raise unknown_name("episode setting", name, names, error=GraspingError)
        try:
            overrides[name] = float(value)
        except ValueError:
            raise GraspingError(f"episode setting {name}: {value!r} is not a number") from None
    return EpisodeConfig(**overrides)


def held_failures(records: list[dict], episode: EpisodeConfig) -> dict:
    """Recorded failures whose object nevertheless ended between both pads and off the table,
    sorted by the fingers' gap: at their closed limit (`tg_drake.outcome.CLOSED_ON_AIR`; the
    label of episodes recorded before the pads' push decided "held", 31fd7cd, called those
    failures) or open past `EpisodeConfig.min_finger_travel` (fingers that never moved)."""
    from tg_drake.grasping.dgi import MAX_OPENING
    from tg_drake.outcome import CLOSED_ON_AIR

    ok = [r for r in records if r.get("status") == "ok"]
    rows = [r for r in ok if not r["success"] and held(r)]
    closed = [r for r in rows if r["finger_gap"] <= CLOSED_ON_AIR]
    open_ = [r for r in rows if r["finger_gap"] >= MAX_OPENING - 2 * episode.min_finger_travel]
    by_category: dict[str, int] = defaultdict(int)
    for r in rows:
        by_category[category(r["object"])] += 1
    return {"n": len(rows), "n_negative": sum(not r["success"] for r in ok),
            "gap_below_min_finger_gap": len(closed),
            "gap_above_travel_limit": len(open_),
            "by_category": dict(sorted(by_category.items(), key=lambda kv: -kv[1]))}


def make_jobs(sample: list[dict], *, nudges: int, distance: float, angle: float, seed: int,
              batch: int, episode: EpisodeConfig) -> list[Job]:
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
                "X_WO": X_WO.ravel().tolist(), "config": asdict(episode),
                "grasps": grasps[b:b + batch]}))
    return jobs


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
    parser.add_argument("--episode", help="episode script changes, e.g. "
                        "shake_amplitude=0.0075,shake_time=0.6: nudges are then compared with "
                        "the exact re-execution (the recorded label is of the old script)")
    parser.add_argument("--key", help="store under label_repeatability_KEY in --results")
    parser.add_argument("--results", type=Path,
                        help="merge the analysis into this JSON file (docs/results/dgi.json)")
    args = parser.parse_args(argv)
    try:
        episode = episode_config(args.episode)
    except GraspingError as e:
        parser.error(str(e))

    if not args.data.is_file():
        raise GraspingError("no grasp records; collect them with tools/collect_grasps.py",
                        file=str(args.data))
    records = [json.loads(line) for line in args.data.read_text().splitlines() if line.strip()]
    sample = stratified_sample(records, args.per_stratum, np.random.default_rng(args.seed),
                               stratum)
    jobs = make_jobs(sample, nudges=args.nudges, distance=args.nudge_mm / 1000,
                     angle=np.radians(args.nudge_deg), seed=args.seed, batch=args.batch,
                     episode=episode)
    print(f"{len(sample)} grasps, {sum(len(j.payload['grasps']) for j in jobs)} episodes in "
          f"{len(jobs)} jobs", flush=True)
    start = time.perf_counter()
    run_jobs(run_grasp_batch, jobs, out=args.out,
             executor=make_executor(args.executor, workers=args.workers, address=args.address))
    keys = {j.key for j in jobs}
    rows = [json.loads(line) for line in args.out.read_text().splitlines() if line.strip()]
    source = {(r["job"], r["index"]): r for r in sample}
    rows = [dict(r, original_held=held(source[(r["source_job"], r["source_index"])]))
            if "source_job" in r else r for r in rows if r["job"] in keys]
    result = analyse(rows, groups=groups,
                     weights=stratum_weights(records, sample, stratum),
                     reference="exact" if args.episode else "recorded")
    result["held_failures"] = held_failures(records, EpisodeConfig())
    # The same nudges labelled by contacts alone (`held`), without the finger-gap rule.
    nudged = [r for r in rows if r.get("status") == "ok" and r["trial"] != "exact"]
    if nudged and not args.episode:
        result["held_rule_nudged_agreement_sample"] = float(np.mean(
            [held(r) == r["original_held"] for r in nudged]))
    result.update(episode=args.episode or "as collected", per_stratum=args.per_stratum,
                  nudges=args.nudges, nudge_mm=args.nudge_mm, nudge_deg=args.nudge_deg,
                  episode_wall_seconds=float(sum(r.get("wall_time", 0.0) for r in rows)),
                  wall_seconds_this_run=time.perf_counter() - start,
                  command="nice -n 10 .venv/bin/python tools/label_noise.py " + " ".join(
                      sys.argv[1:] if argv is None else argv))
    print(json.dumps(result, indent=1))
    if args.results:
        existing = json.loads(args.results.read_text()) if args.results.is_file() else {}
        existing["label_repeatability" + (f"_{args.key}" if args.key else "")] = result
        args.results.write_text(json.dumps(existing, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
