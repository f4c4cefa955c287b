"""Evaluates the kernel category prior like the paper's category table (section VI-C).

    python tools/eval_kernel_prior.py                      # S_SYN analogue, 5 seeds
    python tools/eval_kernel_prior.py --seeds 0 1 --out /tmp/kernel_prior.json

S_SYN analogue ("syn"): every library object sampled `--samplings` times with ground-truth part
labels (as the shipped database); each cloud is a query against the clouds of all *other* objects
(leave-one-object-out: all samplings of the held-out object leave together). For T = 0..15 we
measure the accuracy of the prior's argmax (ties fail) and the mean rank of the true category.
Random is the expectation of a uniformly random ranking; Label fractions is T = 0 (the linear
kernel on label counts); Manifolds is the T with the best accuracy (mean over seeds). Each seed
draws new samplings and new LSH projections.

The T of "manifolds" is chosen inside each leave-one-object-out fold (nested: for every held-out
object, the T with the best accuracy on the other objects alone), so no test object picks it;
"manifolds_best_T" is the paper's way (the T with the best mean test accuracy) beside it.

S_REAL analogue ("perceived"): the shipped database (`tools/build_kernel_db.py`) holds perceived
views of every library object (each resting pose × yaws × viewpoints on the table, ray cast and
put through our perception stage). The queries are its views from the default scenario camera's
viewpoint (0.8 m in front, 0.55 m above the object) at yaws 0°, 120°, 240° (the 264 views of
before); each is compared with the graphs of all *other* objects only (its own object's
perceived views and ground-truth samplings never), and the entries compared with ("all",
"perceived", "ground_truth") and T are chosen by a nested leave-one-object-out on the other
objects. Views where perception found no object, or too small a cloud, are counted apart.

Writes docs/results/kernel_prior.json and kernel_prior.md (the paper's figures alongside).
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys
import time
from pathlib import Path

import numpy as np

from tg_drake.evaluation.paper import PAPER
from tg_drake.kernels.database import ENTRIES, KernelDatabase, load_database
from tg_drake.kernels.evaluation import (
    QUERY_YAWS_DEG,
    Score,
    best,
    evaluate_members,
    leave_one_object_out,
    nested_leave_one_object_out,
    perceived_queries,
    random_score,
)
from tg_drake.kernels.graph import cloud_transition
from tg_drake.kernels.library import SPACING, library_clouds, sample_object
from tg_drake.kernels.propagation import T_MAX, LshProjections, graph_features, normalise
from tg_drake.objects import load_library

RESULTS = Path(__file__).resolve().parents[1] / "docs" / "results"
SHIPPED = Path(__file__).resolve().parents[1] / "tg_drake" / "data" / "kernel_db.npz"

def paper_figures(row: str) -> dict:
    """The paper's accuracy [%], mean rank and T of Random, Label fractions and Manifolds for
    S_SYN ("syn") or the S_REAL datasets ("real"), from tg_drake.evaluation.paper."""
    out = {m: {"accuracy": PAPER["category"][row][m], "mean_rank": PAPER["mean_rank"][row][m]}
           for m in ("random", "label_fractions", "manifolds")}
    out["label_fractions"]["T"] = 0
    out["manifolds"]["T"] = int(PAPER["kernel_T"][row]["manifolds_accuracy"])
    out["manifolds"]["T_rank"] = int(PAPER["kernel_T"][row]["manifolds_rank"])
    return out


# The perceived figures of the database shipped before it held perceived views (commit 5514202:
# ground-truth samplings only, w = 1e-4; T picked on the test accuracy).
BEFORE = {"commit": "5514202", "label_fractions": 0.352, "manifolds": 0.477, "T": 12}


def syn_scores(*, seed: int, samplings: int, spacing: float
               ) -> tuple[list[Score], Score, dict]:
    """Leave-one-object-out scores for T = 0..15 on one set of ground-truth samplings, and the
    nested score (T chosen without the held-out object)."""
    rng = np.random.default_rng(seed)
    clouds, ids, cats = library_clouds(n_samplings=samplings, spacing=spacing, rng=rng)
    projections = LshProjections.sample(t_max=T_MAX, rng=rng)
    features = graph_features([cloud_transition(c) for c in clouds], [c.labels for c in clouds],
                              projections)
    k_hat = normalise(features.kernel())
    nested = nested_leave_one_object_out(k_hat, ids, cats, ids, cats,
                                         {"all": np.ones(len(ids), bool)})
    sizes = np.array([len(c.labels) for c in clouds])
    return leave_one_object_out(k_hat, ids, cats), nested.score, {
        "n_objects": len(set(ids)), "n_queries": len(clouds), "points_min": int(sizes.min()),
        "points_median": float(np.median(sizes)), "points_max": int(sizes.max())}


def summarise(per_seed: list[list[Score]], nested: list[Score]) -> dict:
    """Mean (and spread) over seeds per T, and the paper's three columns: Manifolds with T
    chosen inside the folds (`nested`, one per seed), and with the best mean T as the paper."""
    acc = np.array([[s.accuracy for s in scores] for scores in per_seed])  # (seeds, T + 1)
    rank = np.array([[s.mean_rank for s in scores] for scores in per_seed])
    mean = [Score(float(a), float(r), t) for t, (a, r) in
            enumerate(zip(acc.mean(axis=0), rank.mean(axis=0), strict=False))]
    by_acc, by_rank = best(mean), best(mean, by="mean_rank")
    return {
        "random": random_score().as_dict(),
        "label_fractions": mean[0].as_dict(),
        "manifolds": Score(float(np.mean([n.accuracy for n in nested])),
                           float(np.mean([n.mean_rank for n in nested])),
                           max((n.T for n in nested), key=[n.T for n in nested].count)).as_dict(),
        "manifolds_best_T": by_acc.as_dict(),
        "manifolds_by_rank": by_rank.as_dict(),
        "per_T": [{"T": t, "accuracy": float(acc[:, t].mean()),
                   "accuracy_sd": float(acc[:, t].std(ddof=1)) if len(acc) > 1 else 0.0,
                   "mean_rank": float(rank[:, t].mean()),
                   "mean_rank_sd": float(rank[:, t].std(ddof=1)) if len(rank) > 1 else 0.0}
                  for t in range(acc.shape[1])],
    }


YAWS_DEG = QUERY_YAWS_DEG  # yaws of the perceived queries (from the default viewpoint).


def perceived_scores(db: KernelDatabase) -> dict:
    """Nested leave-one-object-out scores of the perceived queries: Label fractions (T = 0) and
    Manifolds (T chosen in the folds), the entries chosen in the folds too; per T, the plain
    leave-one-object-out with the database's entries and with ground-truth entries only (the
    database before perceived views)."""
    from tg_drake.objects import load_library

    queries = perceived_queries(db)
    ids = db.object_ids[queries]
    lf = evaluate_members(db, queries, t_values=[0])
    mf = evaluate_members(db, queries)
    entries_chosen = [c["entries"] for c in mf.choices.values()]
    library = load_library()
    # The views perception failed on are not in the database: counted when every object the
    # database holds is a shipped one (a database with set b or scan-like objects: not known).
    expected = (sum(len(o.poses) for o in library.values()) * len(YAWS_DEG)
                if set(ids.tolist()) <= set(library) else None)

    def per_t(entries):
        return [{"T": t, "accuracy": float(mf.outcomes[entries, t][0].mean()),
                 "mean_rank": float(mf.outcomes[entries, t][1].mean())}
                for t in range(db.t_max + 1)]

    return {
        "random": random_score().as_dict(),
        "label_fractions": lf.score.as_dict(),
        "manifolds": mf.score.as_dict(),
        "manifolds_choices": mf.choices,
        "entries_chosen": {e: entries_chosen.count(e) for e in ENTRIES},
        "per_T": per_t(db.entries_default),
        "per_T_entries": db.entries_default,
        "per_T_ground_truth_entries": per_t("ground_truth"),
        "n_objects": int(len(set(ids.tolist()))), "n_queries": int(queries.size),
        "n_perception_failures": None if expected is None else int(expected - queries.size),
        "views": [{"object": str(db.object_ids[i]), "pose": str(db.poses[i]),
                   "yaw": float(db.yaws[i])} for i in queries],
    }


def syn_shipped_scores(db: KernelDatabase) -> dict:
    """The database's ground-truth samplings as queries, nested leave-one-object-out like the
    perceived ones (which entries suit a ground-truth cloud)."""
    mf = evaluate_members(db, np.flatnonzero(db.sources == "ground_truth"))
    chosen = [c["entries"] for c in mf.choices.values()]
    return {"manifolds": mf.score.as_dict(),
            "entries_chosen": {e: chosen.count(e) for e in ENTRIES},
            "per_entries": {e: best([Score(float(mf.outcomes[e, t][0].mean()),
                                           float(mf.outcomes[e, t][1].mean()), t)
                                     for t in range(db.t_max + 1)]).as_dict()
                            for e in ENTRIES}}


def shipped_query_times(db: KernelDatabase, n: int = 11) -> dict:
    """Wall time of one prior against the database, for fresh clouds of n objects."""
    objects = list(load_library().values())[::max(1, len(load_library()) // n)][:n]
    rng = np.random.default_rng(12345)
    times = []
    for obj in objects:
        cloud = sample_object(obj, spacing=db.spacing / 2, rng=rng)  # denser than the database.
        db.prior(cloud.points, cloud.normals, cloud.labels)  # warm-up
        t0 = time.perf_counter()
        db.prior(cloud.points, cloud.normals, cloud.labels)
        times.append(time.perf_counter() - t0)
    return {"n_graphs": int(db.object_ids.size), "T": db.t_default,
            "median_ms": float(np.median(times) * 1e3), "max_ms": float(np.max(times) * 1e3)}


def _pct(x: float) -> str:
    return f"{100 * x:.1f}"


def markdown(result: dict) -> str:
    syn, paper, pp = result["syn"], paper_figures("syn"), paper_figures("real")
    perceived, shipped = result.get("perceived"), result["shipped_database"]
    lines = [
        "# Kernel category prior (paper section III-C, Table \"object category\")",
        "",
        f"Command: `{result['command']}`",
        "",
        "Leave-one-object-out over the object library: every query is compared only with the "
        "database graphs of the *other* objects. Accuracy: the prior's argmax is the true "
        "category (ties fail); rank: mean rank of the true category (1 = best; tied categories "
        "share their mean rank). Manifolds: T (and, for perceived queries, the database entries "
        "compared with) chosen inside each fold by leave-one-object-out on the other objects "
        "alone (nested), so no test object picks them; the T shown is the one chosen most often. "
        "\"Best T\" is the paper's way: the T with the best test accuracy.",
        "",
        f"S_SYN analogue: {syn['n_objects']} objects × {result['samplings']} ground-truth "
        f"samplings = {syn['n_queries']} queries per seed against the other objects' samplings, "
        f"seeds {result['seeds']}, voxel {result['spacing']:g} of the object's size "
        f"({syn['points_min']}–{syn['points_max']} points, median {syn['points_median']:.0f}, "
        f"first seed).",
        "",
        "Every cloud, query or database graph, is scaled to a largest principal extent of 1 before "
        "it is resampled (`tg_drake.kernels.graph.size_normalised`), so that T diffusion steps "
        "span the same share of a 6 cm bowl and of a 14 cm glass: the paper's normalised kernel "
        "is meant "
        "to be independent of the objects' scale, which a metric spacing defeats. With the 8 mm "
        "metric spacing of the previous database (commit bb32a56) the same evaluation gave 81.4 % "
        "(S_SYN, nested) and 70.8 % (perceived, nested); the relative spacing 0.05 was chosen "
        "among 0.035–0.07 on leave-one-object-out accuracy (`tools/build_kernel_db.py --spacing`).",
        "",
        "| dataset | measure | Random | Label fractions (T = 0) | Manifolds (nested) | "
        "Manifolds (best T) |",
        "|---|---|---|---|---|---|",
        f"| S_SYN analogue (ours) | accuracy % | {_pct(syn['random']['accuracy'])} | "
        f"{_pct(syn['label_fractions']['accuracy'])} | "
        f"**{_pct(syn['manifolds']['accuracy'])}** (T = {syn['manifolds']['T']}) | "
        f"{_pct(syn['manifolds_best_T']['accuracy'])} (T = {syn['manifolds_best_T']['T']}) |",
        f"| S_SYN (paper) | accuracy % | {paper['random']['accuracy']} | "
        f"{paper['label_fractions']['accuracy']} | — | {paper['manifolds']['accuracy']} "
        f"(T = {paper['manifolds']['T']}) |",
        f"| S_SYN analogue (ours) | mean rank | {syn['random']['mean_rank']:.2f} | "
        f"{syn['label_fractions']['mean_rank']:.2f} | "
        f"**{syn['manifolds']['mean_rank']:.2f}** | "
        f"{syn['manifolds_by_rank']['mean_rank']:.2f} (T = {syn['manifolds_by_rank']['T']}) |",
        f"| S_SYN (paper) | mean rank | {paper['random']['mean_rank']} | "
        f"{paper['label_fractions']['mean_rank']} | — | {paper['manifolds']['mean_rank']} "
        f"(T = {paper['manifolds']['T_rank']}) |",
    ]
    if perceived:
        best_t = best([Score(r["accuracy"], r["mean_rank"], r["T"]) for r in perceived["per_T"]])
        lines += [
            f"| perceived (ours) | accuracy % | {_pct(perceived['random']['accuracy'])} | "
            f"{_pct(perceived['label_fractions']['accuracy'])} | "
            f"**{_pct(perceived['manifolds']['accuracy'])}** "
            f"(T = {perceived['manifolds']['T']}) | {_pct(best_t.accuracy)} (T = {best_t.T}) |",
            f"| perceived (ours) | mean rank | {perceived['random']['mean_rank']:.2f} | "
            f"{perceived['label_fractions']['mean_rank']:.2f} | "
            f"**{perceived['manifolds']['mean_rank']:.2f}** | {best_t.mean_rank:.2f} |"]
    lines += [
        f"| S_REAL (paper) | accuracy % | {pp['random']['accuracy']} | "
        f"{pp['label_fractions']['accuracy']} | — | {pp['manifolds']['accuracy']} "
        f"(T = {pp['manifolds']['T']}) |",
        f"| S_REAL (paper) | mean rank | {pp['random']['mean_rank']} | "
        f"{pp['label_fractions']['mean_rank']} | — | {pp['manifolds']['mean_rank']} "
        f"(T = {pp['manifolds']['T_rank']}) |",
        "",
        "Random is the expectation of a uniformly random ranking of the 11 categories: accuracy "
        "1/11, mean rank (1 + 11)/2 = 6 (the paper writes 5.5).",
        "",
    ]
    if perceived:
        gt = perceived["per_T_ground_truth_entries"]
        gt_best = best([Score(r["accuracy"], r["mean_rank"], r["T"]) for r in gt])
        lines += [
            f"Perceived (S_REAL analogue): {perceived['n_queries']} views of "
            f"{perceived['n_objects']} objects (each resting pose × yaws {list(YAWS_DEG)} from "
            f"the default camera's viewpoint), "
            + ("the views where perception found no object or too small a cloud not counted "
               "(the database holds objects beyond the shipped library)"
               if perceived['n_perception_failures'] is None else
               f"{perceived['n_perception_failures']} more views where perception found no "
               "object or too small a cloud")
            + ". Each is queried against the "
            f"shipped database ({shipped['n_graphs']} graphs: {shipped['n_ground_truth']} "
            f"ground-truth samplings and {shipped['n_perceived']} perceived views from "
            f"{shipped['n_viewpoints']} viewpoint(s)) without any graph of its own object. "
            f"Entries chosen in the folds: {perceived['entries_chosen']}. Against the ground-truth "
            f"samplings alone the same queries reach {_pct(gt[0]['accuracy'])} % at T = 0 and "
            f"{_pct(gt_best.accuracy)} % at best (T = {gt_best.T}); the database shipped before "
            f"(commit {BEFORE['commit']}: ground-truth samplings only, w = 1e-4) gave "
            f"{_pct(BEFORE['label_fractions'])} % and {_pct(BEFORE['manifolds'])} % "
            f"(T = {BEFORE['T']}, picked on the test accuracy).",
            ""]
    if "syn_shipped" in result:
        ss = result["syn_shipped"]
        lines += [
            "Ground-truth samplings of the shipped database as queries (nested, entries chosen "
            f"in the folds: {ss['entries_chosen']}): {_pct(ss['manifolds']['accuracy'])} %, "
            f"mean rank {ss['manifolds']['mean_rank']:.2f}; best T per entries: "
            + ", ".join(f"{e} {_pct(v['accuracy'])} % (T = {v['T']})"
                        for e, v in ss["per_entries"].items()) + ".",
            ""]
    lines += [
        "## Per T (S_SYN analogue: mean ± sd over seeds; perceived: plain leave-one-object-out "
        "with the database's entries, and with its ground-truth samplings only)",
        "",
        "| T | S_SYN acc % | S_SYN rank | perceived acc % | perceived rank | "
        "perceived vs ground truth acc % |",
        "|---|---|---|---|---|---|",
    ]
    for i, r in enumerate(syn["per_T"]):
        pr = perceived["per_T"][i] if perceived else None
        pg = perceived["per_T_ground_truth_entries"][i] if perceived else None
        lines.append(
            f"| {r['T']} | {_pct(r['accuracy'])} ± {_pct(r['accuracy_sd'])} | "
            f"{r['mean_rank']:.2f} ± {r['mean_rank_sd']:.2f} | "
            + (f"{_pct(pr['accuracy'])} | {pr['mean_rank']:.2f} | {_pct(pg['accuracy'])} |"
               if pr else "— | — | — |"))
    lines += [
        "",
        "## Shipped database",
        "",
        f"`tg_drake/data/kernel_db.npz` ({shipped['size_mb']:.1f} MB): {shipped['n_graphs']} "
        f"graphs, LSH bin width w = {shipped['w']:g}; perceived queries compare with its "
        f"{shipped['entries']} entries at T = {shipped['T']}, ground-truth samplings with its "
        f"{shipped['entries_ground_truth']} entries at T = {shipped['T_ground_truth']} (w, "
        "entries and T chosen by leave-one-object-out cross-validation over all objects in "
        "`tools/build_kernel_db.py`, w among 1e-4 (the paper's) to 0.1; the nested evaluation "
        "above re-chooses T and entries per fold but keeps the database's w). "
        f"One prior of a fresh cloud (sampled at half the database spacing, so it is resampled "
        f"first) takes {shipped['median_ms']:.1f} ms median, {shipped['max_ms']:.1f} ms at most, "
        f"over {result['shipped_database_queries']} objects.",
        "",
    ]
    if "speed" in result:
        lines += ["## Speed against GraKeL (same graphs, same kernel values)", "",
                  "| figure | ours | GraKeL | speed-up | reference |", "|---|---|---|---|---|"]
        for name, f in result["speed"].items():
            lines.append(f"| `{name}` | {f['median']:.3g} {f['unit']} | "
                         f"{f['reference_median']:.3g} {f['unit']} | {f['speedup']:.0f}× | "
                         f"{f['reference']} |")
        lines.append("")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4])
    parser.add_argument("--samplings", type=int, default=3, help="clouds per object")
    parser.add_argument("--spacing", type=float, default=SPACING,
                        help="voxel size as a fraction of the object's size")
    parser.add_argument("--database", type=Path, default=None,
                        help="kernel database of the perceived evaluation (default: shipped)")
    parser.add_argument("--bench", action="store_true",
                        help="also run the speed figures kernel_query_ms and kernel_loo_s "
                             "(as `tg-drake bench --only ...`) and add them")
    parser.add_argument("--no-perceived", action="store_true",
                        help="skip the perceived (S_REAL analogue) evaluation")
    parser.add_argument("--out", type=Path, default=RESULTS / "kernel_prior.json",
                        help="JSON output; the Markdown goes beside it (.md)")
    args = parser.parse_args(argv)

    per_seed, nested, info = [], [], None
    for seed in args.seeds:
        t0 = time.perf_counter()
        scores, nested_score, meta = syn_scores(seed=seed, samplings=args.samplings,
                                                spacing=args.spacing)
        info = info or meta
        per_seed.append(scores)
        nested.append(nested_score)
        b = best(scores)
        print(f"seed {seed}: T=0 {scores[0].accuracy:.3f}, best T={b.T} {b.accuracy:.3f}, "
              f"nested {nested_score.accuracy:.3f} ({time.perf_counter() - t0:.1f} s)",
              flush=True)
    syn = {**summarise(per_seed, nested), **info}

    db = load_database(args.database)
    perceived = None
    if not args.no_perceived:
        t0 = time.perf_counter()
        perceived = perceived_scores(db)
        print(f"perceived: {perceived['n_queries']} views, T=0 "
              f"{perceived['label_fractions']['accuracy']:.3f}, nested "
              f"{perceived['manifolds']['accuracy']:.3f} ({time.perf_counter() - t0:.1f} s)",
              flush=True)
    n_timed = 11
    result = {
        "command": "python " + " ".join(shlex.quote(a) for a in
                                        ["tools/eval_kernel_prior.py", *sys.argv[1:]]),
        "seeds": args.seeds, "samplings": args.samplings, "spacing": args.spacing,
        "syn": syn,
        "perceived": perceived,
        "syn_shipped": syn_shipped_scores(db),
        "paper": {"syn": paper_figures("syn"), "perceived": paper_figures("real")},
        "shipped_database": {**shipped_query_times(db, n_timed),
                             "n_ground_truth": int(np.sum(db.sources == "ground_truth")),
                             "n_perceived": int(np.sum(db.sources == "perceived")),
                             "n_viewpoints": int(len(np.unique(
                                 db.viewpoints[db.sources == "perceived"]))),
                             "entries": db.entries_default, "w": db.projections.w,
                             "T_ground_truth": db.t_ground_truth,
                             "entries_ground_truth": db.entries_ground_truth,
                             "size_mb": (args.database or SHIPPED).stat().st_size / 1e6},
        "shipped_database_queries": n_timed,
    }
    if args.bench:
        from dataclasses import asdict

        from tg_drake.kernels import bench

        result["speed"] = {"kernel_query_ms": asdict(bench.kernel_query_ms()),
                           "kernel_loo_s": asdict(bench.kernel_loo_s())}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=2) + "\n")
    args.out.with_suffix(".md").write_text(markdown(result))
    print(args.out.with_suffix(".md").read_text())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
