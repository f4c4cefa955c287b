"""Perception alone through the evaluation's depth sensor, train versus held-out objects.

No physics: the cases of a perceived suite (default: the generalization protocol's, every object
of sets a and b in each resting pose at yaws 0, 120, 240) are run as `tg-drake eval` runs them
(`tg_drake.evaluation.jobs.run_case`: the depth image ray cast, measured by the evaluation sensor
`jobs.EVALUATION_SENSOR` — the D415 model —, seeded by the case; perception; the kernel prior;
the logic), and summarised per side of the object-wise split (`tg_drake.evaluation.split`) and
per category: category (kernel prior argmax, PLM argmax; S_REAL setting), pose and parts
(S_REAL_semi records). The records are those of `tg-drake eval`, so tools/generalization.py
reads them too.

    nice -n 10 .venv/bin/python tools/measure_perception.py --out /tmp/p/results.jsonl
    nice -n 10 .venv/bin/python tools/measure_perception.py --stride 4 --out /tmp/p4.jsonl
    .venv/bin/python tools/measure_perception.py --summary /tmp/p/results.jsonl
    .venv/bin/python tools/measure_perception.py --compare /tmp/run1.jsonl /tmp/run2.jsonl
    .venv/bin/python tools/measure_perception.py --fit /tmp/p/results.jsonl  # fitted inputs
    ... --database /tmp/kernel_db.npz  # another kernel database than the shipped one
    ... --pose-calibration /tmp/pose.json  # another pose likelihood (tools/calibrate_pose.py)

`--stride N` keeps every N-th case (in the suite's order), `--only ID` one object's cases;
`--workers` processes (at most 2 on this machine). `--compare` lists the cases whose records
differ (the repeatability check: the same cases, the same seeds, must give the same records).
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import sys
import time
from pathlib import Path

SUITE = Path(__file__).resolve().parents[1] / "scenarios" / "suites" / "generalization.yaml"
MEASURED = ("category_kernel", "category_plm", "pose", "parts")


def _init(database: str | None, pose_calibration: str | None = None) -> None:
    from tg_drake.evaluation.split import load_split
    load_split().register_libraries()
    if pose_calibration is not None:  # the pose likelihood of this process from that file
        import tg_drake.perception.pose as pose
        pose.CALIBRATION_FILE = Path(pose_calibration)
    if database is not None:  # every kernel prior of this process against that database
        from tg_drake.evaluation.jobs import use_database
        use_database(database)


def _run(case) -> list[dict]:
    from tg_drake.evaluation.jobs import run_case
    out = run_case(case)
    return [{"job": case.key, **r} for r in (out if isinstance(out, list) else [out])]


def run(cases, *, workers: int, database: str | None, pose_calibration: str | None = None
        ) -> list[dict]:
    records: list[dict] = []
    t0 = time.perf_counter()
    if workers <= 1:
        _init(database, pose_calibration)
        results = map(_run, cases)
    else:
        pool = multiprocessing.get_context("spawn").Pool(workers, _init,
                                                         (database, pose_calibration))
        results = pool.imap(_run, cases, chunksize=4)
    for i, recs in enumerate(results, start=1):
        records += recs
        if i % 50 == 0 or i == len(cases):
            print(f"  {i}/{len(cases)} cases, {time.perf_counter() - t0:.0f} s", file=sys.stderr,
                  flush=True)
    if workers > 1:
        pool.close()
        pool.join()
    return records


def summary(records: list[dict]) -> dict:
    """Per side of the split (and per category): kernel prior and PLM argmax (S_REAL), pose and
    parts (S_REAL_semi) [%], with the number of views."""
    from tg_drake.evaluation import tables
    from tg_drake.evaluation.generalization import measures
    from tg_drake.evaluation.split import load_split

    split = load_split()

    def rates(rs):
        m = measures(rs)
        det = tables.detection(rs).get("real_semi", {})
        return {"category_kernel": m["category_kernel"], "category_plm": m["category_plm"],
                "pose": m["pose"], "parts": det.get("part_accuracy"),
                "views": sum(r.get("setting") == "semi" for r in rs)}

    out: dict = {}
    for side in ("train", "held_out"):
        rs = [r for r in records if split.role(r["object"]) == side]
        out[side] = rates(rs) | {"per_category": {
            c: rates([r for r in rs if r["truth"]["category"] == c])
            for c in sorted({r["truth"]["category"] for r in rs})}}
    return out


def print_summary(s: dict) -> None:
    cell = lambda x: "   –" if x is None else f"{x:5.1f}"  # noqa: E731
    print(f"{'':16s}{'side':9s}{'views':>6s}  kernel    PLM   pose  parts")
    for side, m in s.items():
        print(f"{'all':16s}{side:9s}{m['views']:6d}  " + "  ".join(cell(m[k]) for k in MEASURED))
    for c in sorted({c for m in s.values() for c in m["per_category"]}):
        for side, m in s.items():
            r = m["per_category"].get(c)
            if r:
                print(f"{c:16s}{side:9s}{r['views']:6d}  " + "  ".join(cell(r[k])
                                                                      for k in MEASURED))


def _read(path: Path) -> list[dict]:
    with open(path, encoding="utf-8") as f:
        return [json.loads(line) for line in f if line.strip()]


def compare(a: list[dict], b: list[dict]) -> tuple[list[str], int]:
    """The records (job, setting) both files hold that differ, and how many both hold (a subset
    run, `--stride`, is compared with the cases it shares with a whole run)."""
    def keyed(rs):
        return {(r["job"], r.get("setting")): {k: v for k, v in r.items()
                                               if k not in ("wall_s", "worker_pid", "rss_mb")}
                for r in rs}
    ka, kb = keyed(a), keyed(b)
    common = set(ka) & set(kb)
    return sorted(f"{j} [{s}]" for j, s in common if ka[j, s] != kb[j, s]), len(common)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--suite", type=Path, default=SUITE, help="a perceived suite YAML")
    p.add_argument("--stride", type=int, default=1, help="keep every N-th case")
    p.add_argument("--only", action="append", help="only this object's cases (repeatable)")
    p.add_argument("--workers", type=int, default=2, help="processes (default %(default)s)")
    p.add_argument("--database", help="kernel database .npz (default: the shipped one)")
    p.add_argument("--pose-calibration", help="pose likelihood .json (default: the shipped one)")
    p.add_argument("--out", type=Path, help="write the records here (JSON lines)")
    p.add_argument("--summary", type=Path, help="only summarise these records")
    p.add_argument("--fit", type=Path, metavar="RECORDS",
                   help="fit the logic's inputs on these records' training side: the kernel "
                        "prior's floor and the dish-interior miss rate")
    p.add_argument("--compare", type=Path, nargs=2, metavar=("A", "B"),
                   help="list the cases whose records differ between two records files")
    args = p.parse_args(argv)
    if args.fit:
        from tg_drake.evaluation.calibration import dish_interior_miss, prior_floor_of
        from tg_drake.evaluation.split import load_split

        split = load_split()
        train = [r for r in _read(args.fit) if split.role(r["object"]) == "train"]
        eps, n = prior_floor_of(train)
        miss, k, m = dish_interior_miss(train)
        print(f"kernel prior floor (max. likelihood, {n} training views): {eps:.3f}")
        print(f"P(inside unseen | dish upright): {miss:.4f} ({k} of {m} training views, Laplace)")
        return 0
    if args.compare:
        diff, n = compare(_read(args.compare[0]), _read(args.compare[1]))
        print(f"{len(diff)} of the {n} records both hold differ"
              + "".join(f"\n  {d}" for d in diff[:40]))
        return 1 if diff or not n else 0
    if args.summary:
        records = _read(args.summary)
    else:
        from tg_drake.evaluation.split import load_split
        from tg_drake.evaluation.suite import load_suite

        if args.stride < 1:
            p.error("--stride must be ≥ 1")
        load_split().register_libraries()
        suite, cases = load_suite(args.suite)
        if suite.kind != "perceived":
            p.error(f"{args.suite}: a perceived suite is needed (kind: {suite.kind})")
        if args.only:
            cases = [c for c in cases if c.target_placement.id in set(args.only)]
        cases = cases[::args.stride]
        records = run(cases, workers=args.workers, database=args.database,
                      pose_calibration=args.pose_calibration)
        if args.out:
            args.out.parent.mkdir(parents=True, exist_ok=True)
            args.out.write_text("".join(json.dumps(r) + "\n" for r in records))
    s = summary(records)
    print_summary(s)
    return 0


if __name__ == "__main__":
    sys.exit(main())
