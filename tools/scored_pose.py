"""Is the executed grasp pose the one the DGI scored? Runs a sample of scenarios and measures it.

Each run's result.json says, under `grasp.scored_pose`, how the executed grasp pose relates to
the poses the scoring stage scored (`tg_drake.grasping.scoring.scored_pose_match`: `same`, the
nearest scored pose's offset [mm] and angle [deg]). This tool runs scenario files and executed
suite cases (every `--every`-th case of each suite, in the suite's order) through
`tg_drake.run.run_scenario`, streams one line per run to `--out` (JSON Lines, resumable), and
prints the summary: how many runs executed a grasp, how many of those executed a pose the DGI
scored, and the outcomes (placed counts). With `--summarise` it only reads `--out` (or an
evaluation's results.jsonl, whose records carry `grasp.scored_pose` too).

    nice -n 10 .venv/bin/python tools/scored_pose.py --out /tmp/scored.jsonl \
        --scenarios scenarios/*.yaml --suite scenarios/suites/s_grasp.yaml --every 13
    .venv/bin/python tools/scored_pose.py --out /tmp/scored.jsonl --summarise
"""

import argparse
import json
import sys
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path


def _run_one(job: tuple[str, str, int | None]) -> dict:
    """(name, scenario file or suite file, case index or None) → the record of one run."""
    from tg_drake.errors import TgDrakeError
    from tg_drake.run import run_scenario

    name, path, index = job
    try:
        if index is None:
            from tg_drake.scenario import load_scenario
            scenario = load_scenario(path)
        else:
            from tg_drake.evaluation.jobs import scenario_of
            from tg_drake.evaluation.suite import load_suite
            from tg_drake.scenario import Scenario, resolve_objects
            case = load_suite(path)[1][index]
            resolve_objects(Scenario(objects=list(case.objects),
                                     object_libraries=list(case.object_libraries)),
                            where=case.key)
            scenario = scenario_of(case)
        result = run_scenario(scenario, scenario_path=name)
    except TgDrakeError as e:
        return {"name": name, "status": "error", "reason": str(e)}
    grasp = result.get("grasp")
    return {"name": name, "status": result["outcome"]["status"],
            "reason": result["outcome"].get("reason", ""),
            "scored_pose": grasp.get("scored_pose") if grasp else None,
            "grasp": {k: grasp.get(k) for k in ("xyz", "rpy", "part", "p_local", "score")}
            if grasp else None}


def summarise(records: list[dict]) -> dict:
    """Executed grasps, of them the poses the DGI scored, and the outcomes."""
    executed = [r for r in records if (r.get("grasp") or {}).get("xyz") is not None
                or r.get("scored_pose")]
    pose = [((r.get("scored_pose") or (r.get("grasp") or {}).get("scored_pose")) or {})
            for r in executed]
    same = [p.get("same") for p in pose]
    status = Counter(r.get("status") or (r.get("outcome") or {}).get("status") for r in records)
    offsets = [p["offset_mm"] for p in pose if p.get("offset_mm") is not None]
    return {"runs": len(records), "executed_grasps": len(executed),
            "measured": sum(s is not None for s in same),
            "executed_pose_is_scored": sum(bool(s) for s in same),
            "fraction": (sum(bool(s) for s in same) / len(same)) if same else None,
            "max_offset_mm": max(offsets) if offsets else None,
            "outcomes": dict(sorted(status.items(), key=lambda kv: str(kv[0]))),
            "placed": status.get("placed", 0)}


def _read(path: Path) -> list[dict]:
    if not path.exists():
        return []
    records = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    # An evaluation's records keep the outcome and the grasp under their own keys.
    for r in records:
        if "status" not in r and isinstance(r.get("outcome"), dict):
            r["status"] = r["outcome"].get("status")
        if "name" not in r and "job" in r:
            r["name"] = r["job"]
    return records


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, required=True, help="JSON Lines, one run a line")
    parser.add_argument("--scenarios", nargs="*", default=[], type=Path)
    parser.add_argument("--suite", action="append", default=[], type=Path,
                        help="an executed suite: every --every-th case of it")
    parser.add_argument("--every", type=int, default=13)
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--summarise", action="store_true", help="only read --out")
    args = parser.parse_args(argv)
    if args.every < 1:
        parser.error(f"--every must be ≥ 1, got {args.every}")
    if not args.summarise:
        jobs = [(str(p), str(p), None) for p in args.scenarios]
        for suite in args.suite:
            from tg_drake.evaluation.suite import load_suite
            _, cases = load_suite(suite)
            jobs += [(cases[i].key, str(suite), i) for i in range(0, len(cases), args.every)]
        done = {r["name"] for r in _read(args.out)}
        todo = [j for j in jobs if j[0] not in done]
        print(f"{len(jobs)} runs ({len(jobs) - len(todo)} done)", file=sys.stderr)
        args.out.parent.mkdir(parents=True, exist_ok=True)
        with args.out.open("a") as f:
            if args.workers <= 1:
                results = map(_run_one, todo)
            else:
                pool = ProcessPoolExecutor(args.workers)
                results = pool.map(_run_one, todo)
            for r in results:
                f.write(json.dumps(r) + "\n")
                f.flush()
                print(f"{r['name']}: {r['status']}, scored pose "
                      f"{(r.get('scored_pose') or {}).get('same')}", file=sys.stderr)
    print(json.dumps(summarise(_read(args.out)), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
