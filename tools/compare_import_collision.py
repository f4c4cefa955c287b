"""Chooses the import's convex decomposition by what it is for: grasps that hold (issue 18, point
3). Each object's scan-like mesh (tg_drake.scanlike, seed 0: ~50k triangles, mm, y up, holes,
pieces, flipped and zero-area triangles) is imported twice, with CoACD and with V-HACD
(`collision:` of a scenario's mesh entry), and each import runs the whole pipeline once
(`tg_drake.run.run_scenario`): the object alone on the table at the default place, the task that
keeps its pose (p&pInUpright for a standing container, p&pInSideways for a lying tool), judged by
physics (the task outcome: at rest in the task's pose within 5 cm of the target).

    python tools/compare_import_collision.py                    # the first object of each category
    python tools/compare_import_collision.py cup_01 bowl_01 --out /tmp/collision.json

Printed (and written with --out, JSON): per object and backend the import's wall time [s], its
convex pieces, the run's outcome, its task outcome and the run's wall time [s]. The imports go to
a temporary cache (TG_DRAKE_CACHE), never the user's.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import yaml

from tg_drake.objects import get_object, library_by_category
from tg_drake.scanlike import write_scanlike

BACKENDS = ("coacd", "vhacd")
SEED = 0  # of the scan-like meshes


def scenario_text(obj_id: str, mesh_file: Path, backend: str) -> str:
    original = get_object(obj_id)
    pose = "sideways" if original.is_tool else "upright"
    task = "p&pInSideways" if original.is_tool else "p&pInUpright"
    entry = {"mesh": str(mesh_file), "category": original.category, "units": "mm",
             "up_axis": "y", "collision": backend, "mass": original.mass, "pose": pose,
             "xy": [0.0, 0.0], "yaw": 0.0, "name": "scan"}
    return yaml.safe_dump({"objects": [entry], "task": {"task": task, "place_xy": [0.0, -0.3]}},
                          sort_keys=False)


def measure(obj_id: str, backend: str, folder: Path) -> dict:
    from tg_drake.objects import get_object as lookup
    from tg_drake.run import run_scenario
    from tg_drake.scenario import load_scenario

    mesh_file = folder / f"{obj_id}_scan.obj"
    if not mesh_file.exists():
        write_scanlike(obj_id, mesh_file, seed=SEED)
    path = folder / f"{obj_id}_{backend}.yaml"
    path.write_text(scenario_text(obj_id, mesh_file, backend))
    t0 = time.perf_counter()
    scenario = load_scenario(path)  # imports the mesh (into the temporary cache)
    import_s = time.perf_counter() - t0
    imported = lookup(scenario.objects[0].id)
    pieces = len(list(imported.sdf_path.parent.glob("*_collision_*.obj")))
    t0 = time.perf_counter()
    result = run_scenario(scenario, scenario_path=str(path))
    run_s = time.perf_counter() - t0
    task = result["outcome"].get("task_outcome") or {}
    return {"object": obj_id, "backend": backend, "import_s": round(import_s, 1),
            "pieces": pieces, "status": result["outcome"]["status"],
            "reason": result["outcome"]["reason"], "task_success": task.get("success"),
            "task_detail": task.get("detail", ""), "run_s": round(run_s, 1)}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("objects", nargs="*",
                   default=[objs[0].id for objs in library_by_category().values()])
    p.add_argument("--backends", nargs="+", choices=BACKENDS, default=list(BACKENDS))
    p.add_argument("--out", type=Path, help="JSON file for the rows")
    args = p.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory(prefix="tg-collision-") as tmp:
        os.environ["TG_DRAKE_CACHE"] = str(Path(tmp) / "cache")
        for obj_id in args.objects:
            for backend in args.backends:
                row = measure(obj_id, backend, Path(tmp))
                rows.append(row)
                print(json.dumps(row), file=sys.stderr, flush=True)
    print("| object | backend | import [s] | pieces | outcome | task | run [s] |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['object']} | {r['backend']} | {r['import_s']} | {r['pieces']} | "
              f"{r['status']} {r['reason']} | {r['task_success']} | {r['run_s']} |")
    for backend in args.backends:
        mine = [r for r in rows if r["backend"] == backend]
        done = sum(bool(r["task_success"]) for r in mine)
        print(f"{backend}: task done {done}/{len(mine)}, placed "
              f"{sum(r['status'] == 'placed' for r in mine)}/{len(mine)}, import "
              f"{sum(r['import_s'] for r in mine):.0f} s in all")
    if args.out:
        args.out.write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
