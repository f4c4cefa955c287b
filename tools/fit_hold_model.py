"""Collects physics grasp episodes and fits P(hold | features) (tg_drake/data/hold_model.json).

Two steps, each a subcommand:

    # episodes: `--per-scene` grasps of every (object, resting pose), sampled like the DGI data
    # (tg_drake.grasping.dataset.scene_grasps) and executed by the free WSG
    # (tg_drake.simulation.episode): approach, close, lift, shake; label = still held
    nice -n 10 .venv/bin/python tools/fit_hold_model.py collect --out data/hold/episodes.jsonl
    # fit on the split's training objects, report object-wise on the held-out ones
    .venv/bin/python tools/fit_hold_model.py fit --episodes data/hold/episodes.jsonl \
        --out tg_drake/data/hold_model.json

The features of a grasp are those of `tg_drake.grasping.feasibility.hold_features`, computed on
the scene's perception-like cloud (`scene_cloud`: the mesh sampled at perception's voxel, with
noise) and the category prior a perfect classifier would give (its true category): the model
learns how the margins of contact mechanics translate into holds, not how well the category is
recognised.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from dataclasses import asdict
from pathlib import Path

import numpy as np

from tg_drake.errors import ScenarioError
from tg_drake.evaluation.split import load_split
from tg_drake.executor import Job, make_executor, read_records, run_jobs
from tg_drake.grasping.dataset import SamplingConfig, library_scenes, scene_cloud, scene_grasps
from tg_drake.grasping.feasibility import (
    FEATURES,
    FeasibilityConfig,
    HoldModel,
    grasp_feasibility,
    hold_feature_vector,
    hull_volume,
)
from tg_drake.objects import add_library, load_library, mesh
from tg_drake.simulation.episode import TABLE_TOP_Z, EpisodeConfig, run_grasp_batch


def split_ids(ids) -> tuple[list[str], list[str]]:
    """(train, held_out) object ids on the split (scenarios/suites/split.yaml; a scan-like
    version is on its original's side); ids of no set are left out."""
    split = load_split()
    train, held = [], []
    for i in ids:
        try:
            (train if split.role(i) == "train" else held).append(i)
        except ScenarioError:
            continue
    return train, held


def libraries(paths) -> dict:
    """Object id → LibraryObject over the shipped library and the `--library` folders given
    (registered, so that perception finds their objects too)."""
    objects = dict(load_library())
    for path in paths or ():
        objects.update(load_library(path))
        add_library(path)
    return objects


def perceived_cloud(obj, pose: str, seed: int) -> np.ndarray:
    """The completed cloud the feasibility stage sees of `obj` at its resting pose (yaw 0, the
    episode's frame): ray cast from the default camera, through the evaluation's depth sensor
    model (the D415), put through perception."""
    # Here, not at the top: perception's renderer (Open3D) only for `fit --cloud perceived`.
    from tg_drake.evaluation.jobs import EVALUATION_SENSOR
    from tg_drake.perception.render import perceive
    return perceive(obj.id, pose, 0.0, sensor=EVALUATION_SENSOR, seed=seed).p_W


def collect(args) -> int:
    lib = libraries(args.library)
    if args.only:
        unknown = sorted(set(args.only) - set(lib))
        if unknown:
            raise SystemExit(f"--only: no such object {', '.join(unknown)} in the libraries")
        lib = {i: lib[i] for i in args.only}
    rng = np.random.default_rng(args.seed)
    jobs = []
    for obj, pose in library_scenes(lib.values()):
        scene = scene_grasps(obj, pose, seed=args.seed, config=SamplingConfig())
        n = len(scene.X_WG)
        pick = np.sort(rng.choice(n, size=min(args.per_scene, n), replace=False))
        grasps = [{"index": int(i), "kind": str(scene.kinds[i]), "part": int(scene.parts[i]),
                   "X_WG": scene.X_WG[i].ravel().tolist()} for i in pick]
        jobs.append(Job(f"{obj.id}/{pose}", {
            "object": obj.id, "pose": pose, "object_sdf": str(obj.sdf_path),
            "X_WO": scene.X_WO.ravel().tolist(), "config": asdict(EpisodeConfig()),
            "grasps": grasps}))
    # Interleave the objects so that a run stopped early still covers every category.
    jobs = [jobs[i] for i in rng.permutation(len(jobs))]
    args.out.parent.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    run_jobs(run_grasp_batch, jobs, out=args.out,
             executor=make_executor("local", workers=args.workers))
    records = read_records(args.out)
    print(json.dumps({"scenes": len(jobs), "records": len(records),
                      "wall_seconds": time.perf_counter() - start}))
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    c = sub.add_parser("collect", help="run grasp episodes")
    c.add_argument("--out", type=Path, default=Path("data/hold/episodes.jsonl"))
    c.add_argument("--per-scene", type=int, default=16, help="grasps per (object, pose)")
    c.add_argument("--seed", type=int, default=0)
    c.add_argument("--workers", type=int, default=1)
    c.add_argument("--only", action="append", help="only this object (repeatable)")
    f = sub.add_parser("fit", help="fit the hold model on the training objects' episodes")
    f.add_argument("--episodes", type=Path, default=Path("data/hold/episodes.jsonl"))
    f.add_argument("--out", type=Path, default=Path("tg_drake/data/hold_model.json"))
    f.add_argument("--report", type=Path, help="also write the held-out report here")
    f.add_argument("--cloud", choices=("surface", "perceived"), default="surface",
                   help="the cloud the features are computed on: the mesh's noisy surface "
                        "(scene_cloud), or what perception makes of it through the D415 (the "
                        "completed cloud the stage sees at run time)")
    for sp in (c, f):
        sp.add_argument("--library", action="append", type=Path,
                        help="also this library folder (repeatable; e.g. models/objects_b or a "
                             "scan-like library in the cache)")
    args = parser.parse_args(argv)
    if args.command == "collect":
        return collect(args)
    return fit(args, argv)


def hull_densities(ids, lib) -> dict[str, float]:
    """[kg/m³] per category: the median over the objects `ids` of mass / the convex-hull volume
    of their mesh (the volume perception sees)."""
    by_cat: dict[str, list[float]] = {}
    for oid in ids:
        obj = lib[oid]
        V = np.asarray(mesh(obj)[0], float)
        by_cat.setdefault(obj.category, []).append(obj.mass / hull_volume(V))
    return {c: float(np.median(v)) for c, v in sorted(by_cat.items())}


def episode_features(records: list[dict], config: FeasibilityConfig, densities: dict, lib,
                     cloud: str = "surface"
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(F, y, object ids, refused) of the episodes with a label: F (n, len(FEATURES)) the hold
    features of each grasp on its scene's cloud (`cloud`: "surface" or "perceived"), y 1 where
    it held, and whether the stage refuses the grasp outright (the table, or nothing between the
    pads: it gives them 0; they are left out of the fit)."""
    by_scene: dict[tuple[str, str], list[dict]] = {}
    for r in records:
        if r.get("status") == "ok":
            by_scene.setdefault((r["object"], r["pose"]), []).append(r)
    F, y, ids, hit = [], [], [], []
    for (oid, pose), rs in sorted(by_scene.items()):
        obj = lib[oid]
        p_W = (perceived_cloud(obj, pose, seed=0) if cloud == "perceived"
               else scene_cloud(obj, pose, seed=0)[0])
        X = np.array([np.reshape(r["X_WG"], (4, 4)) for r in rs])
        f = grasp_feasibility(X, target_p_W=p_W, others_p_W=np.zeros((0, 3)),
                              table_z=TABLE_TOP_Z, approach=EpisodeConfig().approach_distance,
                              category={obj.category: 1.0},
                              config=dataclasses.replace(config, min_p_hold=0.0),
                              model=dataclasses.replace(
                                  _NEUTRAL, meta={"hull_density_kg_m3": densities}))
        for r, h, c in zip(rs, f.holds, f.collisions, strict=True):
            F.append(hold_feature_vector(h))
            y.append(bool(r["success"]))
            ids.append(oid)
            hit.append(not c.free or h.n_points < 2)
    return np.array(F), np.array(y, int), np.array(ids), np.array(hit)


_NEUTRAL = HoldModel(FEATURES, np.zeros(len(FEATURES)), np.ones(len(FEATURES)),
                     np.zeros(len(FEATURES)), 0.0, {})


def reliability(p: np.ndarray, y: np.ndarray, bins: int = 5) -> list[dict]:
    """Predicted against observed frequency of holding, in equal-width bins of P(hold)."""
    edges = np.linspace(0.0, 1.0, bins + 1)
    k = np.clip(np.digitize(p, edges[1:-1]), 0, bins - 1)
    return [{"bin": [float(edges[i]), float(edges[i + 1])], "n": int((k == i).sum()),
             "mean_p_hold": float(p[k == i].mean()), "held": float(y[k == i].mean())}
            for i in range(bins) if (k == i).any()]


def scores(p: np.ndarray, y: np.ndarray, ids: np.ndarray) -> dict:
    per_object = {o: {"n": int((ids == o).sum()),
                      "accuracy": float(np.mean((p[ids == o] >= 0.5) == y[ids == o])),
                      "held": float(y[ids == o].mean())} for o in np.unique(ids)}
    from sklearn.metrics import roc_auc_score  # scikit-learn only when fitting, like `fit`
    auc = float(roc_auc_score(y, p)) if 0 < y.sum() < len(y) else None
    return {"n": int(len(y)), "held": float(y.mean()),
            "accuracy": float(np.mean((p >= 0.5) == y)), "auc": auc,
            "brier": float(np.mean((p - y) ** 2)),
            "brier_base_rate": float(np.mean((y.mean() - y) ** 2)),
            "reliability": reliability(p, y), "per_object": per_object}


def fit(args, argv) -> int:
    from sklearn.linear_model import LogisticRegression

    records = read_records(args.episodes)
    lib = libraries(args.library)
    train_ids, held_ids = split_ids(sorted(lib))
    densities = hull_densities(train_ids, lib)
    F, y, ids, hit = episode_features(records, FeasibilityConfig(), densities, lib, args.cloud)
    train_ids = [i for i in train_ids if i in set(ids)]
    held_ids = [i for i in held_ids if i in set(ids)]
    train = np.isin(ids, train_ids) & ~hit
    held = np.isin(ids, held_ids) & ~hit
    mean, scale = F[train].mean(axis=0), F[train].std(axis=0) + 1e-9
    lr = LogisticRegression(C=1.0, max_iter=1000).fit((F[train] - mean) / scale, y[train])
    meta = {
        "what": "P(hold | features): logistic regression on the hold margins and contact patch "
                "features of tg_drake.grasping.feasibility, fitted on grasp episodes (lift and "
                "shake, tg_drake.simulation.episode) of the training objects",
        "command": ".venv/bin/python tools/fit_hold_model.py " + " ".join(
            sys.argv[1:] if argv is None else argv),
        "episodes": {"total": int(len(y)), "held": int(y.sum()), "refused": int(hit.sum()),
                     "refused_that_held": int(y[hit].sum())},
        "train_objects": train_ids, "held_out_objects": held_ids,
        "hull_density_kg_m3": densities,
    }
    model = HoldModel(FEATURES, mean, scale, lr.coef_[0], float(lr.intercept_[0]), meta)
    p_train = model.predict_proba(F[train])
    p_held = model.predict_proba(F[held])
    report = {"train": scores(p_train, y[train], ids[train]),
              "held_out": scores(p_held, y[held], ids[held])}
    meta["fit"] = {k: {m: v[m] for m in ("n", "held", "accuracy", "auc", "brier",
                                         "brier_base_rate")}
                   for k, v in report.items()}
    args.out.write_text(json.dumps(model.as_dict(), indent=1) + "\n")
    if args.report:
        args.report.write_text(json.dumps({**meta, **report}, indent=1) + "\n")
    print(json.dumps({**meta, "held_out_reliability": report["held_out"]["reliability"]},
                     indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
