"""Variants of the DGI feature and SVM on the physics-labelled grasps: which one classifies best?

Each variant is a feature setting (`DgiConfig`: image width, depth scale, palm margin; DI and DGI
together or alone) or an SVM setting (class weights, standardised features). For each, γ is
chosen among GAMMAS (or the variant's own grid) by 4-fold stratified cross-validation (the
paper's criterion; C = 1, which every search so far chose) and with it are reported: that
accuracy, the accuracy on unseen objects (4 folds by object) and the top-grasp accuracy on
unseen objects. The choice among variants is made on the
stratified accuracy only, never on the unseen-object figures. Results go to
docs/results/dgi_variants.json; tools/train_dgi.py shows them in dgi.md. Besides the variants:
--learning-curve, --mass-free (labels of the same grasps with every object light) and
--full-information (what a classifier told the scene and the grasp's exact pose reaches, on
--data's labels: a bound on what the data can teach).

    nice -n 10 .venv/bin/python tools/dgi_variants.py --data data/dgi/grasps.jsonl
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

GAMMAS = (0.01, 0.03, 0.1)


@dataclass(frozen=True)
class Variant:
    name: str
    description: str
    config: dict = field(default_factory=dict)  # DgiConfig fields
    columns: str = "both"  # "both", "di" or "dgi"
    class_weight: str | None = None
    standardise: bool = False
    gammas: tuple[float, ...] = GAMMAS


VARIANTS = (
    Variant("shipped", "DI + DGI, 20 × 3 px (the pads' 21 mm), depth × 25, palm margin 21 mm"),
    Variant("di_only", "DI alone", columns="di"),
    Variant("dgi_only", "DGI alone (the paper's name for the feature)", columns="dgi"),
    Variant("paper_volume", "no palm margin (the paper's volume: base to fingertips)",
            {"palm_margin": 0.0}),
    Variant("depth_x10", "depth × 10", {"depth_scale": 10.0}),
    Variant("depth_x50", "depth × 50", {"depth_scale": 50.0}),
    Variant("wide_5", "20 × 5 px (35 mm across the pads)", {"n_v": 5}),
    Variant("wide_7", "20 × 7 px (49 mm across the pads)", {"n_v": 7}),
    Variant("paper_metres", "the paper's units: depth in metres from the base, −1 empty, "
            "no palm margin (γ searched up to the paper's 50)",
            {"depth_scale": 1.0, "palm_margin": 0.0}, gammas=(0.03, 1.0, 10.0, 50.0)),
    Variant("balanced", "class weights balanced", class_weight="balanced"),
    Variant("standardised", "features standardised (per fold)", standardise=True),
)


def features(records: list[dict], variant: Variant, seed: int):
    from tg_drake.grasping.dataset import SamplingConfig, training_set
    from tg_drake.grasping.dgi import DgiConfig

    config = DgiConfig(**variant.config)
    data = training_set(records, seed=seed, config=config, sampling=SamplingConfig())
    n_di = config.n_u * config.n_v
    X = {"both": data.X, "di": data.X[:, :n_di], "dgi": data.X[:, n_di:]}[variant.columns]
    return X, data


def evaluate(variant: Variant, X, data) -> dict:
    from sklearn.model_selection import GroupKFold, StratifiedKFold, cross_val_score
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler
    from sklearn.svm import SVC
    from train_dgi import top_grasp_accuracy  # tools/ is on sys.path when run as a script

    def model(gamma):
        svm = SVC(kernel="rbf", gamma=gamma, C=1.0, class_weight=variant.class_weight)
        return make_pipeline(StandardScaler(), svm) if variant.standardise else svm

    y = data.y
    stratified = StratifiedKFold(4, shuffle=True, random_state=0)
    scores = {g: float(np.mean(cross_val_score(model(g), X, y, cv=stratified)))
              for g in variant.gammas}
    gamma = max(scores, key=scores.get)
    f = np.empty(len(y))
    for train, test in GroupKFold(4).split(X, y, groups=data.object_ids):
        f[test] = model(gamma).fit(X[train], y[train]).decision_function(X[test])
    return {"description": variant.description, "n_features": int(X.shape[1]), "gamma": gamma,
            "cv_accuracy_by_gamma": {str(g): s for g, s in scores.items()},
            "cv_accuracy": scores[gamma],
            "objectwise_accuracy": float(np.mean((f > 0) == y)),
            "top_grasp_accuracy": top_grasp_accuracy(f, y, data.scenes)["accuracy"]}


def learning_curve(X, data, fractions=(0.25, 0.5, 0.75, 1.0), gamma=0.03) -> dict:
    """Accuracy on unseen objects (4 folds by object) of the SVM trained on a random fraction of
    each fold's training grasps: would more grasps of the same kind help?"""
    from sklearn.model_selection import GroupKFold
    from sklearn.svm import SVC

    y = data.y
    rng = np.random.default_rng(0)
    folds = list(GroupKFold(4).split(X, y, groups=data.object_ids))
    curve = {}
    for fraction in fractions:
        right = np.zeros(len(y), dtype=bool)
        n_train = []
        for train, test in folds:
            keep = np.sort(rng.choice(train, size=int(round(fraction * len(train))),
                                      replace=False))
            n_train.append(len(keep))
            right[test] = SVC(kernel="rbf", gamma=gamma, C=1.0).fit(
                X[keep], y[keep]).predict(X[test]) == y[test]
        curve[str(fraction)] = {"n_train_mean": float(np.mean(n_train)),
                                "objectwise_accuracy": float(np.mean(right))}
    return curve


def mass_free_labels(records: list[dict], light: list[dict], seed: int, mass: float) -> dict:
    """The shipped feature and SVM on labels from the same grasps executed with every object at
    one light mass (`tools/collect_grasps.py --object-mass`): accuracy on those labels, and the
    model trained on them judged by the real-mass labels (grasps executed fine in both sets)."""
    from sklearn.model_selection import GroupKFold
    from sklearn.svm import SVC
    from train_dgi import top_grasp_accuracy

    from tg_drake.grasping.dataset import training_order
    from tg_drake.objects import get_object

    shipped = VARIANTS[0]
    X, data = features(light, shipped, seed)
    own = evaluate(shipped, X, data)
    real = {(r["job"], r["index"]): r for r in records if r.get("status") == "ok"}
    both = [r for r in light if r.get("status") == "ok" and (r["job"], r["index"]) in real]
    X, data = features(both, shipped, seed)
    ordered = training_order(both)
    y_real = np.array([int(real[(r["job"], r["index"])]["success"]) for r in ordered])
    f = np.empty(len(data.y))
    for train, test in GroupKFold(4).split(X, data.y, groups=data.object_ids):
        f[test] = SVC(kernel="rbf", gamma=own["gamma"], C=1.0).fit(
            X[train], data.y[train]).decision_function(X[test])
    same = defaultdict(list)
    for r, y in zip(ordered, y_real, strict=False):
        same[get_object(r["object"]).category].append(int(r["success"]) == y)
    ok = [r for r in light if r.get("status") == "ok"]
    return {"mass_kg": mass, "n_grasps": len(ok), "n_positive": sum(bool(r["success"]) for r in ok),
            "n_ok_both": len(both), **{k: own[k] for k in (
                "gamma", "cv_accuracy", "objectwise_accuracy", "top_grasp_accuracy")},
            "judged_by_real_labels": {
                "objectwise_accuracy": float(np.mean((f > 0) == y_real)),
                "top_grasp_accuracy": top_grasp_accuracy(f, y_real, data.scenes)["accuracy"]},
            "same_label_per_category": {c: float(np.mean(v)) for c, v in sorted(same.items())}}


def full_information(X, data) -> dict:
    """How far could a classifier get that knows more than local shape? Gradient-boosted trees
    (4-fold stratified, as the variants) on the DGI alone, on the scene's identity (object and
    resting pose, one-hot) with the grasp's pose relative to the cloud's centroid (rotation and
    offset: the grasp exactly, which with the scene fixes the label up to its noise), and on
    both. A bound on what the data can teach, not a model to ship."""
    from sklearn.ensemble import HistGradientBoostingClassifier
    from sklearn.model_selection import StratifiedKFold, cross_val_score

    y = data.y
    scenes = np.unique(data.scenes)
    where = np.hstack([(data.scenes[:, None] == scenes[None]).astype(float),
                       data.X_WG[:, :3, :3].reshape(len(y), 9),
                       data.X_WG[:, :3, 3] - data.centroids])
    stratified = StratifiedKFold(4, shuffle=True, random_state=0)
    out = {"classifier": "HistGradientBoostingClassifier(max_iter=400, learning_rate=0.05)",
           "n_grasps": int(len(y))}
    for name, F in (("dgi", X), ("scene_and_pose", where), ("dgi_scene_and_pose",
                                                              np.hstack([where, X]))):
        model = HistGradientBoostingClassifier(max_iter=400, learning_rate=0.05, random_state=0)
        out[name] = float(np.mean(cross_val_score(model, F, y, cv=stratified)))
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=Path("data/dgi/grasps.jsonl"))
    parser.add_argument("--seed", type=int, default=0, help="the collection's seed")
    parser.add_argument("--variants", help="comma-separated names (default: all)")
    parser.add_argument("--out", type=Path, default=Path("docs/results/dgi_variants.json"))
    parser.add_argument("--learning-curve", action="store_true",
                        help="the shipped feature's accuracy on unseen objects against the share "
                        "of training grasps (only that, unless --variants is given)")
    parser.add_argument("--mass-free", type=Path, metavar="DATA",
                        help="grasps collected with --object-mass: compare their labels (only "
                        "that, unless --variants is given)")
    parser.add_argument("--mass-free-kg", type=float, default=0.1,
                        help="the --object-mass those grasps were collected with [kg]")
    parser.add_argument("--full-information", action="store_true",
                        help="the bound of a classifier that knows the scene and the grasp's "
                        "exact pose, on --data's labels (only that, unless --variants is given)")
    parser.add_argument("--merge", action="store_true",
                        help="add to the variants already in --out instead of replacing them")
    args = parser.parse_args(argv)
    names = [v.name for v in VARIANTS]
    chosen = args.variants.split(",") if args.variants else names
    unknown = [n for n in chosen if n not in names]
    if unknown:
        from tg_drake.errors import GraspingError, unknown_name

        parser.error(str(unknown_name("DGI variant", unknown[0], names, error=GraspingError)))
    records = [json.loads(line) for line in args.data.read_text().splitlines() if line.strip()]
    results = {}
    commands = []
    curve = None
    n_ok = int(sum(r.get("status") == "ok" for r in records))
    n_grasps = n_ok  # the variants' data: kept from --out unless variants run on --data
    if args.merge and args.out.is_file():
        previous = json.loads(args.out.read_text())
        results = previous["variants"]
        commands = previous.get("commands") or [previous["command"]]
        curve = previous.get("learning_curve")
        mass_free = previous.get("mass_free_labels")
        full = previous.get("full_information") or {}
        n_grasps = previous.get("n_grasps", n_grasps)
    else:
        mass_free, full = None, {}
    if args.mass_free:
        light = [json.loads(line) for line in args.mass_free.read_text().splitlines()
                 if line.strip()]
        mass_free = mass_free_labels(records, light, args.seed, args.mass_free_kg)
        print("mass-free labels", json.dumps(mass_free), flush=True)
    if args.learning_curve:
        X, data = features(records, VARIANTS[0], args.seed)
        curve = learning_curve(X, data)
        print("learning curve", json.dumps(curve), flush=True)
    if args.full_information:
        X, data = features(records, VARIANTS[0], args.seed)
        full[args.data.stem] = full_information(X, data)
        print("full information", json.dumps(full[args.data.stem]), flush=True)
    evaluated = False
    for variant in VARIANTS:
        if variant.name not in chosen or ((args.learning_curve or args.mass_free
                                           or args.full_information) and not args.variants):
            continue
        start = time.perf_counter()
        X, data = features(records, variant, args.seed)
        results[variant.name] = evaluate(variant, X, data)
        results[variant.name]["seconds"] = time.perf_counter() - start
        evaluated = True
        print(variant.name, json.dumps(results[variant.name]), flush=True)
    best = max(results, key=lambda n: results[n]["cv_accuracy"]) if results else None
    results = {v.name: {**results[v.name], "description": v.description} for v in VARIANTS
               if v.name in results}
    commands.append("nice -n 10 .venv/bin/python tools/dgi_variants.py " + " ".join(
        sys.argv[1:] if argv is None else argv))
    out = {"variants": results, "best_by_cv_accuracy": best, "C": 1.0,
           "n_grasps": n_ok if evaluated else n_grasps, "commands": commands}
    if curve:
        out["learning_curve"] = curve
    if mass_free:
        out["mass_free_labels"] = mass_free
    if full:
        out["full_information"] = full  # by the data file's name (grasps, grasps_light)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(out, indent=1) + "\n")
    print(f"best by cross-validated accuracy: {best}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
