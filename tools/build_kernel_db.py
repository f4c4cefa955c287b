"""Builds the kernel-prior database shipped with the package (tg_drake/data/kernel_db.npz).

    nice -n 10 python tools/build_kernel_db.py --workers 2   # generated objects only
    python tools/build_kernel_db.py --scanlike --workers 2  # the shipped file: with the
    #   training objects' scan-like versions (tools/make_scanlike.py --all --import [--library
    #   models/objects_b] first; a scan-like version and its original are one object for
    #   leave-one-object-out)
    python tools/build_kernel_db.py --check         # rebuild and compare with the shipped file
    python tools/build_kernel_db.py --samplings 5 --out /tmp/kernel_db.npz
    python tools/build_kernel_db.py --objects all-a --sensor ideal  # the database before the split

The objects are the **training objects** of the object-wise split (`tg_drake.evaluation.split`:
sets a and b), so that held-out objects are in no database graph (`--objects all-a`: every
object of the shipped library, as before the split). Two kinds of graphs per object:

- ground-truth samplings (`--samplings`): uniform on the mesh, random rotation, one point per
  voxel on a shifted grid, the mesh's part labels (the S_SYN analogue);
- perceived views: the object alone on the table in each of its resting poses, turned by each
  yaw of `tg_drake.kernels.library.VIEW_YAWS_DEG` (between the evaluation suites' 0, 120, 240),
  its depth image ray cast from each of the first `--viewpoints` of `VIEWPOINTS` (default: the
  default camera's alone), measured by the evaluation's depth sensor model (the D415,
  `--sensor`; seeded per view by `--seed`) and put through our perception stage
  (`describe_scene`); the perceived cloud with its estimated part labels, resampled like a
  query. A perceived query then meets perceived
  graphs, as the paper compared real scans with real scans.

Then the LSH projections are drawn, every graph is hashed for t = 0..15, and the LSH bin width w,
the T and the entries a perceived query is compared with ("all", "perceived" or "ground_truth")
are chosen by leave-one-object-out cross-validation: every perceived view is a query against the
graphs of all other objects, the choice with the best accuracy (then mean rank, then the larger
w, the smaller T) wins. At that choice, the same leave-one-object-out priors give the prior's
floor ε for each kind of query (the maximum-likelihood ε of (1 − ε)·prior + ε/11 for the true
category): the logic sees the prior calibrated so (`KernelDatabase.floor`). The paper's
w = 1e-4 is one of the candidates; the coarser bins that
perceived clouds favour also keep the file small. The file holds the hashed counts, the
projections, where each graph came from and the choice. Everything
follows from `--seed` (perception, ray casting and the seeded sensor model are deterministic, in
any process), so a rebuild gives the same file; `--check` verifies that.
"""

from __future__ import annotations

import argparse
import io
import sys
import time
from pathlib import Path

import numpy as np

from tg_drake.errors import KernelError
from tg_drake.kernels.database import ENTRIES, KernelDatabase, prepare_cloud
from tg_drake.kernels.evaluation import query_outcomes
from tg_drake.kernels.graph import K_NEIGHBOURS
from tg_drake.kernels.library import (
    SPACING,
    VIEW_YAWS_DEG,
    VIEWPOINTS,
    library_clouds,
    library_fingerprint,
    perceived_views,
)
from tg_drake.kernels.prior import category_priors, fit_prior_floor
from tg_drake.kernels.propagation import BIN_WIDTH, T_MAX, LshProjections
from tg_drake.perception.sensor_model import IdealDepth, StructuredLight
from tg_drake.types import CATEGORIES, SCANLIKE_SUFFIX, source_objects

OUT = Path(__file__).resolve().parents[1] / "tg_drake" / "data" / "kernel_db.npz"
BIN_WIDTHS = (BIN_WIDTH, 1e-3, 1e-2, 3e-2, 1e-1)  # LSH bin widths w cross-validated.
# The evaluation's depth sensor (tg_drake.evaluation.jobs.EVALUATION_SENSOR, the D415 model).
SENSORS = {"d415": StructuredLight(), "ideal": IdealDepth()}


def object_ids(which: str, scanlike: bool = False) -> list[str]:
    """The database's objects: the split's training objects (sets a and b) or all of set a;
    `scanlike`: with the scan-like version (<id>_scan) of each, from the scan-like libraries
    `tools/make_scanlike.py --all --import [--library L]` writes (registered here)."""
    from tg_drake.evaluation.split import load_split  # a tool: may read the evaluation's split
    from tg_drake.importing.cache import scanlike_library
    from tg_drake.objects import add_library, load_library

    if which == "all-a":
        ids, libraries = list(load_library()), [None]
    else:
        split = load_split()
        split.register_libraries()
        ids = list(split.train)
        libraries = [None if s.shipped else s.library for s in split.sets.values()]
    if not scanlike:
        return ids
    for library in libraries:
        folder = scanlike_library(library)
        if not (folder / "library.yaml").is_file():
            raise SystemExit(f"no scan-like library at {folder}: make it first with "
                             "python tools/make_scanlike.py --all --import"
                             + ("" if library is None else f" --library {library}"))
        add_library(folder)
    return ids + [f"{i}{SCANLIKE_SUFFIX}" for i in ids]


def _progress(done: int, total: int) -> None:
    if done % 100 == 0 or done == total:
        print(f"  perceived {done}/{total}", flush=True)


def cross_validate(db: KernelDatabase, clouds: str = "perceived") -> tuple[dict, dict]:
    """Leave-one-object-out accuracy and mean rank of every graph of one source (`clouds`) as a
    query, for each choice of entries and T. Returns (the best choice, all scores keyed
    "entries/T")."""
    queries = np.flatnonzero(db.sources == clouds)
    if queries.size == 0:
        raise KernelError(f"no {clouds} graphs to cross-validate on")
    rows = db.member_profile(queries)
    ids = source_objects(db.object_ids)  # a scan-like version is its original's object
    not_own = ids[queries][:, None] != ids[None, :]
    scores = {}
    for entries in ENTRIES:
        allowed = not_own & db.entry_mask(entries)[None, :]
        for t in range(db.t_max + 1):
            correct, rank = query_outcomes(rows[t], allowed, db.categories,
                                           db.categories[queries])
            scores[entries, t] = (float(correct.mean()), float(rank.mean()))
    entries, t = min(scores, key=lambda c: (-scores[c][0], scores[c][1], c[1],
                                            ENTRIES.index(c[0])))
    return ({"entries": entries, "T": t, "accuracy": scores[entries, t][0],
             "mean_rank": scores[entries, t][1]},
            {f"{e}/{t}": v for (e, t), v in scores.items()})


def fitted_floor(db: KernelDatabase, clouds: str, entries: str, t: int) -> float:
    """The prior's floor ε for queries of one source (`clouds`) at the chosen entries and T: the
    maximum-likelihood ε of (1 − ε)·prior + ε/11 over the leave-one-object-out priors of the
    database's own graphs of that source (`tg_drake.kernels.prior.fit_prior_floor`)."""
    queries = np.flatnonzero(db.sources == clouds)
    ids = source_objects(db.object_ids)
    allowed = (ids[queries][:, None] != ids[None, :]) & db.entry_mask(entries)[None, :]
    priors, _ = category_priors(np.where(allowed, db.member_profile(queries)[t], -np.inf),
                                db.categories)
    return fit_prior_floor(priors, db.categories[queries])


def build(*, samplings: int, spacing: float, seed: int, viewpoints=VIEWPOINTS,
          yaws_deg=VIEW_YAWS_DEG, object_ids=None, k: int = K_NEIGHBOURS,
          widths=BIN_WIDTHS, views: tuple[list[dict], list[dict]] | None = None,
          sensor=None, map_fn=map) -> tuple[KernelDatabase, dict]:
    """The database and a summary of it (sizes, the cross-validated choice).

    `views`: (views, failures) from `perceived_views` when already perceived (else perceived
    here, through `sensor`, seeded by `seed`, mapped by `map_fn`). `widths`: the LSH bin widths
    to choose from; all share one draw of projections (the offsets b scale with w)."""
    rng = np.random.default_rng(seed)
    clouds, ids, cats = library_clouds(n_samplings=samplings, spacing=spacing, rng=rng,
                                       object_ids=object_ids)
    n_gt = len(clouds)
    unit = LshProjections.sample(t_max=T_MAX, w=1.0, rng=rng)
    views, failures = views if views is not None else perceived_views(
        object_ids=object_ids, viewpoints=viewpoints, yaws_deg=yaws_deg, sensor=sensor,
        seed=seed, progress=_progress, map_fn=map_fn)
    kept, dropped = [], []
    for v in views:
        d = v["description"]
        try:
            clouds.append(prepare_cloud(d.p_W, d.n_W, d.labels, spacing=spacing, k=k))
        except KernelError as e:  # a sliver of a cloud: too small for the graph
            dropped.append({k: v[k] for k in ("object", "pose", "yaw", "view")} |
                           {"reason": str(e)})
            continue
        kept.append(v)
        ids.append(v["object"])
        cats.append(CATEGORIES.index(v["category"]))
    n_views = len(kept)
    db, chosen, scores = None, None, {}
    for w in widths:
        candidate = KernelDatabase.build(
            clouds, ids, cats, spacing=spacing, k=k,
            projections=LshProjections(v=unit.v, b=unit.b * w, w=float(w)),
            sources=["ground_truth"] * n_gt + ["perceived"] * n_views,
            poses=[""] * n_gt + [v["pose"] for v in kept],
            yaws=[np.nan] * n_gt + [v["yaw"] for v in kept],
            viewpoints=[-1] * n_gt + [v["view"] for v in kept])
        best_here, scores_here = cross_validate(candidate)
        print(f"  w = {w:g}: entries {best_here['entries']}, T = {best_here['T']}, accuracy "
              f"{best_here['accuracy']:.3f}, mean rank {best_here['mean_rank']:.2f}", flush=True)
        scores.update({f"{w:g}/{key}": v for key, v in scores_here.items()})
        if chosen is None or (-best_here["accuracy"], best_here["mean_rank"], -w) < \
                (-chosen["accuracy"], chosen["mean_rank"], -chosen["w"]):
            db, chosen = candidate, {**best_here, "w": float(w)}
    db.t_default, db.entries_default = chosen["T"], chosen["entries"]
    # Ground-truth samplings as queries (the synthetic evaluation, perfect perception): their
    # own choice of entries and T at the chosen w.
    chosen_gt, _ = cross_validate(db, "ground_truth")
    db.t_ground_truth, db.entries_ground_truth = chosen_gt["T"], chosen_gt["entries"]
    db.floor_default = fitted_floor(db, "perceived", db.entries_default, db.t_default)
    db.floor_ground_truth = fitted_floor(db, "ground_truth", db.entries_ground_truth,
                                         db.t_ground_truth)
    # Of the generated objects: a scan-like version follows from its original and the seed.
    db.library_fingerprint = library_fingerprint(sorted(set(source_objects(ids).tolist())))
    sizes = np.array([len(c.labels) for c in clouds])
    return db, {"n_objects": len(set(ids)), "n_graphs": len(clouds), "n_ground_truth": n_gt,
                "n_perceived": n_views, "perception_failures": failures,
                "too_small": dropped, "points_min": int(sizes.min()),
                "points_median": float(np.median(sizes)), "points_max": int(sizes.max()),
                "chosen": chosen, "chosen_ground_truth": chosen_gt, "cv_scores": scores}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samplings", type=int, default=3,
                        help="ground-truth samplings per library object")
    parser.add_argument("--spacing", type=float, default=SPACING,
                        help="voxel size as a fraction of the object's size")
    parser.add_argument("--seed", type=int, default=0, help="seed of sampling and projections")
    parser.add_argument("--out", type=Path, default=OUT, help="output .npz")
    parser.add_argument("--objects", choices=("train", "all-a"), default="train",
                        help="the split's training objects (default) or all of set a")
    parser.add_argument("--scanlike", action="store_true",
                        help="add the scan-like version of each object (tools/make_scanlike.py "
                             "--all --import, for each set's library, first)")
    parser.add_argument("--sensor", choices=tuple(SENSORS), default="d415",
                        help="depth sensor model of the perceived views (default %(default)s)")
    parser.add_argument("--workers", type=int, default=1, help="processes perceiving views")
    parser.add_argument("--viewpoints", type=int, default=1,
                        choices=range(1, len(VIEWPOINTS) + 1),
                        help="the first N of tg_drake.kernels.library.VIEWPOINTS (default "
                             "%(default)s: the default camera's, the evaluation's)")
    parser.add_argument("--check", action="store_true",
                        help="rebuild in memory and compare with --out instead of writing it")
    args = parser.parse_args(argv)

    t0 = time.perf_counter()
    ids = object_ids(args.objects, args.scanlike)
    pool = None
    if args.workers > 1:
        import multiprocessing
        pool = multiprocessing.get_context("spawn").Pool(
            args.workers, object_ids, (args.objects, args.scanlike))  # registers the libraries
    try:
        db, summary = build(samplings=args.samplings, spacing=args.spacing, seed=args.seed,
                            object_ids=ids, viewpoints=VIEWPOINTS[:args.viewpoints],
                            sensor=SENSORS[args.sensor],
                            map_fn=map if pool is None else
                            (lambda f, jobs: pool.imap(f, jobs, chunksize=8)))
    finally:
        if pool is not None:
            pool.close()
            pool.join()
    print(f"{summary['n_graphs']} graphs of {summary['n_objects']} objects "
          f"({summary['n_ground_truth']} ground-truth samplings, {summary['n_perceived']} "
          f"perceived views; {len(summary['perception_failures'])} views without an object, "
          f"{len(summary['too_small'])} too small), {summary['points_min']}–"
          f"{summary['points_max']} points (median {summary['points_median']:.0f}) at "
          f"a spacing of {args.spacing:g} of the object's size")
    c = summary["chosen"]
    print(f"cross-validated for perceived queries: w = {c['w']:g}, entries {c['entries']}, "
          f"T = {c['T']}: "
          f"leave-one-object-out accuracy {c['accuracy']:.3f}, mean rank {c['mean_rank']:.2f}")
    print(f"fitted prior floors (maximum likelihood, leave-one-object-out): perceived "
          f"{db.floor_default:.3f}, ground truth {db.floor_ground_truth:.3f}")
    g = summary["chosen_ground_truth"]
    print(f"cross-validated for ground-truth samplings as queries: entries {g['entries']}, "
          f"T = {g['T']}: accuracy {g['accuracy']:.3f}, mean rank {g['mean_rank']:.2f}")
    if args.check:
        buffer = io.BytesIO()
        db.save(buffer)
        buffer.seek(0)
        if not args.out.is_file():
            print(f"{args.out} is missing", file=sys.stderr)
            return 1
        same = _same(KernelDatabase.load(buffer), KernelDatabase.load(args.out))
        print(f"{args.out} {'matches' if same else 'DIFFERS from'} the rebuild "
              f"({time.perf_counter() - t0:.1f} s)")
        return 0 if same else 1
    args.out.parent.mkdir(parents=True, exist_ok=True)
    db.save(args.out)
    print(f"wrote {args.out} ({args.out.stat().st_size / 1e6:.2f} MB) in "
          f"{time.perf_counter() - t0:.1f} s")
    return 0


def _same(a: KernelDatabase, b: KernelDatabase) -> bool:
    """Equal contents (the .npz bytes hold zip timestamps, so compare the arrays)."""
    fa, fb = a.features, b.features
    return (a.floor_default == b.floor_default and a.floor_ground_truth == b.floor_ground_truth
            and np.array_equal(a.object_ids, b.object_ids)
            and np.array_equal(a.categories, b.categories)
            and np.array_equal(a.sources, b.sources) and np.array_equal(a.poses, b.poses)
            and np.array_equal(a.yaws, b.yaws, equal_nan=True)
            and np.array_equal(a.viewpoints, b.viewpoints)
            and (a.spacing, a.k, a.t_default, a.entries_default, a.t_ground_truth,
                 a.entries_ground_truth, a.library_fingerprint, a.projections.w)
            == (b.spacing, b.k, b.t_default, b.entries_default, b.t_ground_truth,
                b.entries_ground_truth, b.library_fingerprint, b.projections.w)
            and np.array_equal(a.projections.v, b.projections.v)
            and np.array_equal(a.projections.b, b.projections.b)
            and all(np.array_equal(x, y)
                    for x, y in zip(fa.vocabularies, fb.vocabularies, strict=False))
            and all((x != y).nnz == 0 for x, y in zip(fa.counts, fb.counts, strict=False)))


if __name__ == "__main__":
    raise SystemExit(main())
