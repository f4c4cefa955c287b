"""Collects physics-labelled grasps on the object library for the DGI classifier.

For every library object in every resting pose that suits it, the grasps of
`tg_drake.grasping.dataset.scene_grasps` (part-box pre-grasps, perturbed copies, random ones) are
executed by a free-floating WSG 50 in hydroelastic contact (`tg_drake.simulation.episode`):
approach,
close, lift, shake; the label is whether the object stays between the fingers. Jobs (batches of
grasps on one scene) go through the executor interface and their records stream to JSON Lines; a
rerun skips finished batches. A summary (counts per object and label, throughput) is written next
to the data and, with --summary, to docs/results/dgi_dataset_summary.json.

    nice -n 10 python tools/collect_grasps.py --out data/dgi/grasps.jsonl --workers 1
    python tools/collect_grasps.py --objects cup_01,knife_02 --out data/dgi/try.jsonl
    python tools/collect_grasps.py --object-mass 0.1 --workers 2 --out data/dgi/grasps_light.jsonl
    python tools/collect_grasps.py --executor ray --address auto --out data/dgi/grasps.jsonl
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import Counter, defaultdict
from dataclasses import asdict
from pathlib import Path

import numpy as np

from tg_drake.errors import TgDrakeError
from tg_drake.executor import EXECUTORS, Job, finished_jobs, make_executor, read_records, run_jobs
from tg_drake.grasping.dataset import SamplingConfig, library_scenes, scene_grasps
from tg_drake.objects import get_object, load_library
from tg_drake.outputs import check_output_file
from tg_drake.simulation.episode import EpisodeConfig, run_grasp_batch


def make_jobs(objects, *, seed: int, batch: int, sampling: SamplingConfig,
              episode: EpisodeConfig) -> tuple[list[Job], int]:
    """Jobs of at most `batch` grasps of one scene; also how many hypotheses the table ruled out."""
    jobs, through_table = [], 0
    for obj, pose in library_scenes(objects):
        scene = scene_grasps(obj, pose, seed=seed, config=sampling)
        through_table += scene.n_through_table
        grasps = [{"index": i, "kind": str(k), "part": int(p), "X_WG": X.ravel().tolist()}
                  for i, (X, k, p) in enumerate(zip(scene.X_WG, scene.kinds, scene.parts,
                                                    strict=False))]
        for b in range(0, len(grasps), batch):
            jobs.append(Job(f"{obj.id}/{pose}/{b // batch}", {
                "object": obj.id, "pose": pose, "object_sdf": str(obj.sdf_path),
                "X_WO": scene.X_WO.ravel().tolist(), "config": asdict(episode),
                "grasps": grasps[b:b + batch]}))
    return jobs, through_table


def recorded_masses(out: Path) -> set[float]:
    """The --object-mass values (0.0: the objects' own) the grasps already in `out` ran with."""
    return {float(r.get("object_mass", 0.0)) for r in read_records(out)}


def summarise(records: list[dict], *, seed: int, through_table: int) -> dict:
    """Counts per object and label, failures by reason, and the time per grasp."""
    per_object: dict[str, Counter] = defaultdict(Counter)
    per_kind: dict[str, Counter] = defaultdict(Counter)
    reasons: Counter = Counter()
    for r in records:
        if r.get("status") == "ok":
            label = "positive" if r["success"] else "negative"
        else:
            label = "sim_error"
            reasons[r.get("reason", "?")] += 1
        per_object[r.get("object", r["job"].split("/")[0])][label] += 1
        if "kind" in r:
            per_kind[r["kind"]][label] += 1
    total = Counter()
    for c in per_object.values():
        total.update(c)
    times = np.array([r["wall_time"] for r in records if "wall_time" in r])
    return {
        "seed": seed,
        "n_grasps": int(total["positive"] + total["negative"]),
        "n_positive": int(total["positive"]),
        "n_negative": int(total["negative"]),
        "n_sim_error": int(total["sim_error"]),
        "n_through_table_skipped": through_table,
        "sim_error_reasons": dict(reasons.most_common()),
        "per_kind": {k: dict(v) for k, v in sorted(per_kind.items())},
        "per_object": {k: dict(v) for k, v in sorted(per_object.items())},
        "seconds_per_grasp_median": float(np.median(times)) if len(times) else None,
        "seconds_per_grasp_mean": float(np.mean(times)) if len(times) else None,
    }


def main(argv=None) -> int:
    try:
        return collect(argv)
    except TgDrakeError as e:  # a bad --out, results file or executor option
        print(f"collect_grasps.py: error: {e}", file=sys.stderr)
        return 2


def collect(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("data/dgi/grasps.jsonl"))
    parser.add_argument("--objects", help="comma-separated object ids (default: the library)")
    parser.add_argument("--executor", choices=EXECUTORS, default="local")
    parser.add_argument("--workers", type=int, default=1,
                        help="local processes (0: in this process); with ray: jobs in flight")
    parser.add_argument("--address", help="Ray cluster address (with --executor ray)")
    parser.add_argument("--batch", type=int, default=20, help="grasps per job")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--object-mass", type=float, default=0.0,
                        help="> 0: every object weighs this much [kg] (its inertia scaled, its "
                             "shape and centre of mass kept): labels of local shape alone")
    parser.add_argument("--max-grasps", type=int, default=None,
                        help="each scene's grasps drawn at random down to this many (default: all)")
    parser.add_argument("--summary", type=Path,
                        help="also write the summary here (docs/results/dgi_dataset_summary.json)")
    args = parser.parse_args(argv)

    objects = ([get_object(o) for o in args.objects.split(",")] if args.objects
               else list(load_library().values()))
    if args.max_grasps is not None and args.max_grasps < 1:
        parser.error(f"--max-grasps must be ≥ 1, got {args.max_grasps}")
    if args.object_mass < 0:
        parser.error(f"--object-mass must be ≥ 0 kg, got {args.object_mass}")
    episode = EpisodeConfig(object_mass=args.object_mass)
    check_output_file(args.out, what="--out file")
    mixed = recorded_masses(args.out) - {args.object_mass}
    if mixed:  # a rerun skips the finished jobs: their labels would be of another mass
        parser.error(f"{args.out} holds grasps executed with --object-mass "
                     f"{', '.join(f'{m:g}' for m in sorted(mixed))} (0: the objects' own masses), "
                     f"not {args.object_mass:g}: choose another --out")
    jobs, through_table = make_jobs(objects, seed=args.seed, batch=args.batch,
                                    sampling=SamplingConfig(max_grasps=args.max_grasps),
                                    episode=episode)
    n_grasps = sum(len(j.payload["grasps"]) for j in jobs)
    done = finished_jobs(args.out)
    print(f"{len(objects)} objects, {n_grasps} grasps in {len(jobs)} jobs "
          f"({len(done & {j.key for j in jobs})} done); {through_table} through the table skipped")
    start = time.perf_counter()
    run = run_jobs(run_grasp_batch, jobs, out=args.out,
                   executor=make_executor(args.executor, workers=args.workers,
                                          address=args.address))
    wall = time.perf_counter() - start

    keys = {j.key for j in jobs}
    records = [r for r in read_records(args.out) if r["job"] in keys]
    summary = summarise(records, seed=args.seed, through_table=through_table)
    summary["object_mass_kg"] = args.object_mass or None  # None: every object at its own mass
    ran = sum(len(j.payload["grasps"]) for j in jobs if j.key not in done)
    summary["this_run"] = {"grasps": ran, "wall_seconds": wall, "workers": args.workers,
                           "executor": args.executor,
                           "grasps_per_wall_second": ran / wall if wall > 0 and ran else None,
                           "job_errors": run.n_errors}
    summary["command"] = "nice -n 10 .venv/bin/python tools/collect_grasps.py " + " ".join(
        sys.argv[1:] if argv is None else argv)
    text = json.dumps(summary, indent=1)
    args.out.with_suffix(".summary.json").write_text(text + "\n")
    if args.summary:
        args.summary.parent.mkdir(parents=True, exist_ok=True)
        args.summary.write_text(text + "\n")
    print(json.dumps({k: v for k, v in summary.items() if k != "per_object"}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
