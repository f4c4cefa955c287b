"""Every table of the paper's section VI, derived from a sweep's records, beside the paper's
figures.

`compute(records)` → a JSON-able dict of tables; `markdown(tables, command=...)` → tables.md.
Records are what tg_drake.evaluation.jobs writes (one line of results.jsonl each); a case that
crashed is a record with "error" and counts as a failure of every measure it enters.

Measures are the paper's (VI-B): accuracy in %; category from the argmax, ties failing (and, for
the uniform prior, the second definition "ties ok"); task and pre-grasp E_i on set-valued ground
truth: Pr = the predictions down to the (|Gt| − i)-th largest probability (ties at the boundary
included, so a tie that spills out of Gt fails), a success if Pr ⊆ Gt; i = 0 is the strictest,
and cases with |Gt| ≤ i use |Gt| − i = 1. Part detection: the set of detected parts equals the
object's. For executed runs (paper: "# correctly estimated part / # valid grasping hypotheses"), a
pre-grasp is a success when the executed grasp's part is in Gt and the object stayed in the hand
through the lift, over the runs whose planner found a grasp to execute.

Task success (ours; `task_success`): the task suites' runs (dataset "tasks") judged by physics —
result.json's `task_outcome.success` (poured fraction, resting pose, surface, receiver's hold) —
per task and variant, over all runs and over the runs with a reachable pre-grasp (a plan was
made), on train and held-out objects (the split). It needs no ground truth written from the
theory's knowledge; the executed E0 beside it does (the acceptable parts).
"""

from __future__ import annotations

import re
from collections import defaultdict

import numpy as np

from tg_drake.evaluation.paper import PAPER
from tg_drake.evaluation.suite import DATASETS, OURS, VARIANTS
from tg_drake.types import CATEGORIES, PART_LABELS, TASKS

# Probabilities this close are tied (the circuit's rounding is ~1e-15; records keep 6 digits).
TIE = 1e-9
THRESHOLDS = (0.5, 0.4, 0.3)  # P(grasp | local shape) thresholds of the paper's Table "pipeline"
HELD = ("lifted", "placed")  # outcomes where the object stayed in the hand through the lift
LOGIC_METHODS = ("plm_uniform", "plm_general_uniform", "plm", "plm_general")
CATEGORY_METHODS = ("random", "label_fractions", "manifolds", *LOGIC_METHODS)
ABLATION_METHODS = ("plm_top", "plm_nonexclusive", "plm_paper_observations")
LABELS = {"random": "Random", "label_fractions": "Label fractions", "manifolds": "Manifolds",
          "plm_uniform": "PLM_uniform", "plm_general_uniform": "PLM^general_uniform",
          "plm": "PLM", "plm_general": "PLM^general", "plm_top": "PLM, top category only",
          "plm_nonexclusive": "PLM, not mutually exclusive",
          "plm_paper_observations": "PLM, the paper's observations only", "local": "Local",
          "pipeline": "Pipeline", "pipeline_uniform": "Pipeline_uniform",
          "random_part": "Random part"}
TASK_DATASET = "tasks"  # the task suites' dataset (scenarios/suites/tasks_*.yaml)
# The command of the full task suites (every object of both sets that affords each task, four
# variants; hours on two cores). The pass suite needs the receiver, the task pass's default.
TASK_SUITES_COMMAND = ("nice -n 10 tg-drake eval scenarios/suites/tasks_*.yaml --out out/tasks "
                       "--tables docs/results --name tasks --workers 2")
SPLIT_ROLES = ("train", "held_out")

def top_set(p: np.ndarray) -> set[int]:
    """Indices tied at the maximum (empty when everything is 0)."""
    p = np.asarray(p, dtype=float)
    return set(np.flatnonzero(p >= p.max() - TIE).tolist()) if p.size and p.max() > 0 else set()


def e_success(p, truth: set[int], i: int) -> bool:
    """E_i: the predictions down to the (|Gt| − i)-th largest (ties included) lie in Gt."""
    p = np.asarray(p, dtype=float)
    if not truth or p.max(initial=0.0) <= 0:
        return False
    k = max(len(truth) - i, 1)
    threshold = np.sort(p)[::-1][k - 1]
    return bool(threshold > 0 and set(np.flatnonzero(p >= threshold - TIE).tolist()) <= truth)


def _vector(d: dict | None, names) -> np.ndarray:
    d = d or {}
    return np.array([float(d.get(n, 0.0)) for n in names])


def _pct(ok: list[bool]) -> float | None:
    return round(100.0 * float(np.mean(ok)), 2) if ok else None


def _argmax_ok(p, truth_index: int) -> bool:
    return top_set(p) == {truth_index}


def _by_dataset(records: list[dict]) -> dict[str, list[dict]]:
    out = defaultdict(list)
    for r in records:
        out[r["dataset"]].append(r)
    return {d: out[d] for d in DATASETS if d in out}


def _logic(records):
    return [r for r in records if r.get("kind") in ("synthetic", "perceived")]


def _executed(records, variant=None):
    return [r for r in records if r.get("kind") == "executed"
            and (variant is None or r.get("variant") == variant)]


def _status(r) -> str:
    return (r.get("outcome") or {}).get("status", "failed")


def _handed_over(r) -> bool:
    """A pass whose receiver held the object (outcome lifted: the robot let go in the air)."""
    task = (r.get("outcome") or {}).get("task_outcome") or {}
    return _status(r) == "lifted" and task.get("task") == "pass" and bool(task.get("success"))


def delivered(r) -> bool:
    """The paper's "placed": the object put down where the task wants it, or for a pass handed
    over to the receiver (the pass's place is the receiver's hand)."""
    return _status(r) == "placed" or _handed_over(r)


def _not_delivered_reason(r) -> str:
    """Why a run did not deliver: its outcome's reason, "not handed over" for a pass the receiver
    did not take, "error" and the error's start for a crashed case."""
    if "error" in r:
        return r["error"][:40] or "error"
    out = r.get("outcome") or {}
    if out.get("reason"):
        return out["reason"]
    task = out.get("task_outcome") or {}
    return "not handed over" if task.get("task") == "pass" else out.get("status", "failed")


def _method(r, method):
    m = (r.get("methods") or {}).get(method)
    return m if m and "error" not in m else None


def detection(records) -> dict:
    out = {}
    for dataset, rs in _by_dataset(records).items():
        rows = []
        for r in rs:
            if r.get("kind") == "perceived" and r.get("setting") in ("semi", None):
                d = r.get("detection") or {}
                rows.append((r["pose"], bool(d.get("pose_ok")), bool(d.get("parts_ok"))))
            elif r.get("kind") == "executed" and r.get("variant") == "pipeline":
                p = r.get("perception") or {}
                found = sorted(k for k, v in (p.get("parts") or {}).items() if v > 0)
                rows.append((r["pose"], p.get("pose") == r["pose"],
                             found == sorted(r.get("object_parts", []))))
        if not rows:
            continue
        us = [x for x in rows if x[0] in ("upright", "sideways")]
        out[dataset] = {"n": len(rows), "pose_accuracy": _pct([x[1] for x in rows]),
                        "part_accuracy": _pct([x[2] for x in rows]),
                        "upright_sideways": {"n": len(us),
                                             "pose_accuracy": _pct([x[1] for x in us]),
                                             "part_accuracy": _pct([x[2] for x in us])}}
    return out


def _per_object(logic) -> list[dict]:
    """Synthetic records: the first of each object (its prior is the object's); other kinds: all
    (a perceived prior is one per view)."""
    seen: dict = {}
    for r in logic:
        seen.setdefault(r["object"] if r.get("kind") == "synthetic" else r["job"] + str(
            r.get("setting")), r)
    return list(seen.values())


def per_category(records) -> dict:
    """Category accuracy (argmax, ties fail) per true category, for each logic dataset: the
    kernel prior (Manifolds, per object as in `category`) and the logic methods."""
    out = {}
    for dataset, rs in _by_dataset(records).items():
        logic = _logic(rs)
        if not logic:
            continue
        table: dict = {}
        for c in CATEGORIES:
            mine = [r for r in logic if r["truth"]["category"] == c]
            if not mine:
                continue
            i = CATEGORIES.index(c)
            table[c] = {"n": len(mine), "manifolds": _pct([
                r.get("priors") is not None and _argmax_ok(r["priors"]["manifolds"], i)
                for r in _per_object(mine)])}
            for m in LOGIC_METHODS:
                table[c][m] = _pct([_method(r, m) is not None and
                                    _argmax_ok(_method(r, m)["category"], i) for r in mine])
        out[dataset] = table
    return out


def impossible_evidence(records) -> dict:
    """Per logic dataset and method: the cases whose observations have probability 0 under the
    method's theory (a kernel prior certain of a category the observed parts rule out); they
    count as failures of every measure."""
    out = {}
    for dataset, rs in _by_dataset(records).items():
        counts = {m: sum(1 for r in _logic(rs)
                             if "error" in ((r.get("methods") or {}).get(m) or {}))
                  for m in (*LOGIC_METHODS, *ABLATION_METHODS)}
        if _logic(rs):
            out[dataset] = {m: n for m, n in counts.items() if n}
    return out


def category(records) -> dict:
    out = {}
    for dataset, rs in _by_dataset(records).items():
        table: dict = {"random": round(100.0 / len(CATEGORIES), 2)}
        logic = _logic(rs)
        if logic:
            truth = [CATEGORIES.index(r["truth"]["category"]) for r in logic]
            # A synthetic prior is one per object (one labelled sampling of its mesh), so its
            # accuracy is over the objects, as the paper's S_SYN Manifolds (36 of 41 objects).
            objects = _per_object(logic)
            table["n_objects"] = len(objects)
            for prior in ("label_fractions", "manifolds"):
                table[prior] = _pct([r.get("priors") is not None and _argmax_ok(
                    r["priors"][prior], CATEGORIES.index(r["truth"]["category"]))
                    for r in objects])
            for m in (*LOGIC_METHODS, *ABLATION_METHODS):
                table[m] = _pct([_method(r, m) is not None and
                                 _argmax_ok(_method(r, m)["category"], t)
                                 for r, t in zip(logic, truth, strict=False)])
            for m in ("plm_uniform", "plm_general_uniform"):
                table[f"{m}_ties_ok"] = _pct([_method(r, m) is not None and
                                              t in top_set(_method(r, m)["category"])
                                              for r, t in zip(logic, truth, strict=False)])
            table["n"] = len(logic)
        for variant, method in (("pipeline", "plm"), ("pipeline_uniform", "plm_uniform")):
            ex = _executed(rs, variant)
            if not ex:
                continue
            truth = [CATEGORIES.index(r["truth"]["category"]) for r in ex]
            if variant == "pipeline":
                table["manifolds"] = _pct([_argmax_ok(_vector(r.get("category_prior"), CATEGORIES),
                                                      t) for r, t in zip(ex, truth, strict=False)])
                table["n"] = len(ex)
            table[method] = _pct([_argmax_ok(_vector(r.get("category"), CATEGORIES), t)
                                  for r, t in zip(ex, truth, strict=False)])
        out[dataset] = table
    return out


def _max_i(records, key) -> int:
    sizes = [len(r["truth"]["tasks"]) if key == "task" else len(parts)
             for r in records for parts in ([None] if key == "task" else
                                            r["truth"]["parts"].values())]
    return max(sizes, default=1) - 1


def task(records) -> dict:
    out = {}
    for dataset, rs in _by_dataset(records).items():
        logic = _logic(rs)
        if not logic:
            continue
        n_i = _max_i(logic, "task") + 1
        sizes = [len(r["truth"]["tasks"]) for r in logic]
        table = {"n": len(logic), "gt_sizes": {str(k): sizes.count(k) for k in sorted(set(sizes))}}
        for m in (*LOGIC_METHODS, *ABLATION_METHODS):
            table[m] = {}
            for i in range(n_i):
                table[m][f"E{i}"] = _pct([
                    _method(r, m) is not None and e_success(
                        _method(r, m)["task"], {TASKS.index(t) for t in r["truth"]["tasks"]}, i)
                    for r in logic])
        out[dataset] = table
    return out


def pregrasp(records) -> dict:
    out = {}
    for dataset, rs in _by_dataset(records).items():
        table: dict = {}
        logic = _logic(rs)
        if logic:
            pairs = [(r, t, {PART_LABELS.index(p) for p in parts}) for r in logic
                     for t, parts in r["truth"]["parts"].items() if parts]
            n_i = max((len(s) for _, _, s in pairs), default=1)
            table["n_pairs"] = len(pairs)
            table["no_grasp_pairs"] = sum(1 for r in logic for p in r["truth"]["parts"].values()
                                          if not p)
            for m in (*LOGIC_METHODS, *ABLATION_METHODS):
                table[m] = {f"E{i}": _pct([_method(r, m) is not None and
                                           e_success(_method(r, m)["part"][t], s, i)
                                           for r, t, s in pairs]) for i in range(n_i)}
        for variant in VARIANTS:
            ex = [r for r in _executed(rs, variant) if r["task_given"] in r["truth"]["parts"]
                  and r["truth"]["parts"][r["task_given"]]]
            if not ex:
                continue
            valid = [r for r in ex if r.get("grasp")]
            gt = [(r, set(r["truth"]["parts"][r["task_given"]])) for r in valid]
            table[variant] = {
                "n_runs": len(ex), "n_valid": len(valid),
                # the executed grasp's part is acceptable and the object stayed in the hand
                "E0_executed": _pct([r["grasp"]["part"] in s and _status(r) in HELD
                                     for r, s in gt]),
                # the logic's most likely part alone (ties fail), over every run
                "E0_logic": _pct([e_success(_vector(r.get("part"), PART_LABELS),
                                            {PART_LABELS.index(p) for p in
                                             r["truth"]["parts"][r["task_given"]]}, 0)
                                  for r in ex]) if variant not in ("local", "random_part")
                else None}
        if table:
            out[dataset] = table
    return out


def _scenario_id(r) -> str:
    return r["job"].split("/", 1)[1].split("@")[0]


def pipeline_vs_local(records) -> dict:
    out = {}
    for dataset, rs in _by_dataset(records).items():
        ex = _executed(rs)
        variants = sorted({r["variant"] for r in ex})
        if len(variants) < 2:
            continue
        ids = [{_scenario_id(r) for r in ex if r["variant"] == v} for v in variants]
        common = set.intersection(*ids)
        table: dict = {"n_scenarios": len(common)}
        for v in ("local", "pipeline", "pipeline_uniform", "random_part"):
            runs = [r for r in ex if r["variant"] == v and _scenario_id(r) in common]
            if not runs:
                continue
            held = [r for r in runs if _status(r) in HELD and r.get("grasp")
                    and r["grasp"].get("p_local") is not None]
            table[v] = {"n_held": len(held), "held_rate": _pct([_status(r) in HELD for r in runs]),
                        **{f"{t}": _pct([r["grasp"]["p_local"] < t for r in held])
                           for t in THRESHOLDS}}
        out[dataset] = table
    return out


def grasp_and_place(records) -> dict:
    """The paper's table per number of objects, over its datasets' analogues (ours, e.g. the
    sweep, are in `outcomes`)."""
    by_n: dict = defaultdict(list)
    for r in _executed(records, "pipeline"):
        if r["dataset"] not in OURS:
            by_n[str(r["n_objects"])].append(r)
    out = {}
    for n, rs in sorted(by_n.items()):
        reachable = [r for r in rs if r.get("grasp")]
        out[n] = {"datasets": sorted({r["dataset"] for r in rs}), "total": len(rs),
                  "reachable": len(reachable), "reachable_pct": _pct([bool(r.get("grasp"))
                                                                     for r in rs]),
                  "grasped": sum(_status(r) in ("grasped", *HELD) for r in reachable),
                  "placed": sum(delivered(r) for r in reachable),
                  "failures": _failures(rs)}
        for k in ("grasped", "placed"):
            out[n][f"{k}_pct"] = (round(100.0 * out[n][k] / len(reachable), 2)
                                  if reachable else None)
    return out


def outcomes(records) -> dict:
    """Executed runs per dataset and variant, over all runs: grasped (the object in the hand at
    some point), lifted (held through the lift), placed; failures by reason; per category the
    count of each outcome; median wall time per run [s]."""
    reached = {"grasped": ("grasped", *HELD), "lifted": HELD}
    out: dict = {}
    for dataset, rs in _by_dataset(records).items():
        for variant in VARIANTS:
            ex = _executed(rs, variant)
            if not ex:
                continue
            per_category: dict = defaultdict(lambda: defaultdict(int))
            for r in ex:
                row = per_category[r["truth"]["category"]]
                row["n"] += 1
                row[_status(r) if "error" not in r else "error"] += 1
            wall = [r["timings"]["total"] for r in ex if (r.get("timings") or {}).get("total")]
            out.setdefault(dataset, {})[variant] = {
                "n": len(ex),
                **{k: _pct([_status(r) in v for r in ex]) for k, v in reached.items()},
                "placed": _pct([delivered(r) for r in ex]),
                "failures": _failures(ex),
                "per_category": {c: dict(per_category[c]) for c in CATEGORIES if c in per_category},
                "wall_seconds_median": round(float(np.median(wall)), 2) if wall else None}
    return out


def _task_success(r) -> bool:
    """The run's task check in physics succeeded (a crashed case or one without a check fails)."""
    t = (r.get("outcome") or {}).get("task_outcome") or {}
    return bool(t.get("success")) and "error" not in r


def _e0_executed(r) -> bool | None:
    """The executed grasp's part is acceptable and the object was held through the lift; None
    without a planned grasp or an acceptable part set."""
    parts = r["truth"]["parts"].get(r.get("task_given") or "")
    if not parts or not r.get("grasp"):
        return None
    return r["grasp"]["part"] in parts and _status(r) in HELD


def _success_row(rs: list[dict]) -> dict:
    reachable = [r for r in rs if r.get("grasp")]
    e0 = [x for x in map(_e0_executed, rs) if x is not None]
    return {"n": len(rs), "success": _pct([_task_success(r) for r in rs]),
            "n_reachable": len(reachable),
            "success_reachable": _pct([_task_success(r) for r in reachable]),
            "n_e0": len(e0), "E0_executed": _pct(e0)}


def _task_rows(task_success: dict):
    """(task, variant, row) of the task-success table, the derived Pipeline − Local row left out
    (the text and the markdown tables both list these)."""
    for task_name, by_variant in task_success.items():
        for v, r in by_variant.items():
            if v != "pipeline_minus_local":
                yield task_name, v, r


def task_success(records) -> dict:
    """Task success in physics per task × variant (the task suites' runs): over all runs and over
    the runs with a reachable pre-grasp, on each side of the split, with the executed E0 (the
    set-valued measure, on the same runs) and the task checks' failure details."""
    ex = [r for r in _executed(records) if r["dataset"] == TASK_DATASET and r.get("task_given")]
    out: dict = {}
    for t in TASKS:
        for v in VARIANTS:
            rs = [r for r in ex if r["task_given"] == t and r["variant"] == v]
            if not rs:
                continue
            row = _success_row(rs)
            row["split"] = {side: _success_row([r for r in rs if r.get("split") == side])
                            for side in SPLIT_ROLES}
            failed: dict = defaultdict(int)
            for r in rs:
                if not _task_success(r):
                    o = r.get("outcome") or {}
                    why = ((o.get("task_outcome") or {}).get("detail") or o.get("reason")
                           or r.get("error", "error"))
                    if o.get("status") == "failed" and o.get("reason"):  # ended before the task
                        why = f"run failed: {o['reason']}"
                    failed[" ".join(str(why).split())[:60]] += 1
            row["failures"] = dict(sorted(failed.items(), key=lambda kv: -kv[1]))
            if t == "pass":  # the part the receiver holds after a successful hand-over
                received: dict = defaultdict(int)
                for r in rs:
                    if _task_success(r):
                        m = ((r.get("outcome") or {}).get("task_outcome") or {}).get("measure")
                        received[(m or {}).get("received_part") or "unknown"] += 1
                row["received"] = dict(sorted(received.items(), key=lambda kv: -kv[1]))
            out.setdefault(t, {})[v] = row
        if t in out and "pipeline" in out[t] and "local" in out[t]:
            p, lo = out[t]["pipeline"]["success"], out[t]["local"]["success"]
            out[t]["pipeline_minus_local"] = (None if p is None or lo is None
                                              else round(p - lo, 2))
    return out


def task_success_text(t: dict) -> str:
    """The task-success table as plain text (what `tg-drake eval` prints)."""
    rows = t.get("task_success") or {}
    if not rows:
        return ""
    lines = ["task success in physics [%] (all runs / runs with a reachable pre-grasp; "
             "train | held-out, all runs):"]
    for task_name, v, r in _task_rows(rows):
        sp = r["split"]
        lines.append(f"  {task_name:16s} {LABELS[v]:17s} {r['n']:4d} runs  "
                     f"{_f(r['success']):>6s} / {_f(r['success_reachable']):>6s}  "
                     f"({_f(sp['train']['success'])} | {_f(sp['held_out']['success'])})  "
                     f"E0 executed {_f(r['E0_executed'])}")
    return "\n".join(lines)


def _failures(rs) -> dict:
    counts: dict = defaultdict(int)
    for r in rs:
        if not delivered(r):
            counts[_not_delivered_reason(r)] += 1
    return dict(sorted(counts.items(), key=lambda kv: -kv[1]))


def ablations(cat: dict, tsk: dict, pre: dict) -> dict:
    top, excl, interior = {}, {}, {}
    for dataset in tsk:
        def row(m, dataset=dataset):
            return {"category": cat[dataset].get(m), "task_E0": tsk[dataset][m]["E0"],
                    "pregrasp_E0": pre.get(dataset, {}).get(m, {}).get("E0")}
        top[dataset] = {"full_prior": row("plm"), "top_category": row("plm_top")}
        interior[dataset] = {"with": row("plm"), "without": row("plm_paper_observations")}
        ex, non = row("plm"), row("plm_nonexclusive")
        excl[dataset] = {"exclusive": ex, "nonexclusive": non, "difference": {
            k: None if ex[k] is None or non[k] is None else round(ex[k] - non[k], 2) for k in ex}}
    diffs = {k: [e["difference"][k] for e in excl.values() if e["difference"][k] is not None]
             for k in ("category", "task_E0", "pregrasp_E0")}
    return {"top_category": top, "exclusive": excl, "interior": interior,
            "exclusive_mean_difference": {k: round(float(np.mean(v)), 2) if v else None
                                          for k, v in diffs.items()}}


def compute(records: list[dict]) -> dict:
    """Every table from the records of a sweep."""
    cat, tsk, pre = category(records), task(records), pregrasp(records)
    counts: dict = defaultdict(lambda: defaultdict(int))
    for r in records:
        counts[r["dataset"]][r.get("variant") or r.get("setting") or r["kind"]] += 1
    return {"n_records": len(records),
            "n_errors": sum("error" in r for r in records),
            "records_per_dataset": {d: dict(v) for d, v in counts.items()},
            "detection": detection(records), "category": cat, "task": tsk, "pregrasp": pre,
            "per_category": per_category(records),
            "impossible_evidence": impossible_evidence(records),
            "pipeline_vs_local": pipeline_vs_local(records),
            "grasp_and_place": grasp_and_place(records), "outcomes": outcomes(records),
            "task_success": task_success(records),
            "ablations": ablations(cat, tsk, pre), "paper": PAPER}


# -- Markdown ----------------------------------------------------------------------------------

def _f(x) -> str:
    return "–" if x is None else (f"{x:.2f}" if isinstance(x, float) else str(x))


def _both(ours, paper) -> str:
    return f"**{_f(ours)}** ({_f(paper)})" if paper is not None else f"**{_f(ours)}**"


def _text(lines: list[str]) -> str:
    """The page, one blank line between blocks (a section left out leaves no gap)."""
    return re.sub(r"\n{3,}", "\n\n", "\n".join(lines)).rstrip("\n") + "\n"


def markdown(t: dict, *, command: str, notes: str = "") -> str:
    P = PAPER
    def name(d):
        return DATASETS.get(d, d) + ("" if d in OURS else " analogue")

    L = ["# The paper's section VI tables on our suites", "",
         f"Command: `{command}`", "",
         "Every number is derived from `results.jsonl` by `tg_drake.evaluation.tables` (accuracy "
         "in %). Each cell: **ours** (the paper's figure, – where the paper has none). Suites: "
         "`scenarios/suites/` (S_SYN: perfect observations; S_REAL_*: rendered and perceived; "
         "S_GRASP, S_ROBOT: executed in simulation). Ground truth: "
         "`scenarios/suites/ground_truth.yaml` (rules/README.md Tables 3 and 5) and the scenes' "
         "own sets; it is written down from the same knowledge the theory encodes, not labelled "
         "by people as the paper's.", ""]
    if notes:
        L += [notes, ""]
    L += [f"Records: {t['n_records']} ({t['n_errors']} crashed cases, counted as failures): "
          + ", ".join(f"{name(d)} {dict(v)}" for d, v in t["records_per_dataset"].items()), ""]

    # A section whose table would be empty (no suite of its kind given) is left out.
    if t["detection"]:
        L += ["## Pose and part detection (paper Table \"visualRepresentation\")", "",
              "| dataset | views | pose | parts | upright + sideways: pose | parts |",
              "|---|---|---|---|---|---|"]
    for d, r in t["detection"].items():
        p = P["detection"].get(d, {})
        L.append(f"| {name(d)} | {r['n']} | {_f(r['pose_accuracy'])} | {_f(r['part_accuracy'])} "
                 f"| {_both(r['upright_sideways']['pose_accuracy'], p.get('pose_accuracy'))} | "
                 f"{_both(r['upright_sideways']['part_accuracy'], p.get('part_accuracy'))} |")

    L += ["", "## Category (paper Table \"object_category_graphkernel\"; argmax, ties fail)", "",
          "| dataset | " + " | ".join(LABELS[m] for m in CATEGORY_METHODS) + " |",
          "|---|" + "---|" * len(CATEGORY_METHODS)]
    for d, r in t["category"].items():
        p = P["category"].get(d, {})
        L.append(f"| {name(d)} | " + " | ".join(_both(r.get(m), p.get(m))
                                                  for m in CATEGORY_METHODS) + " |")
    L += ["", "Second definition (ties count as success) for the uniform prior: " + "; ".join(
        f"{name(d)}: PLM_uniform **{_f(r.get('plm_uniform_ties_ok'))}**, PLM^general_uniform "
        f"**{_f(r.get('plm_general_uniform_ties_ok'))}**" for d, r in t["category"].items()
        if "plm_uniform_ties_ok" in r) + " (paper: " + "; ".join(
        f"{DATASETS[d]}{' datasets' if d == 'real' else ''} {_f(v['plm_uniform'])} and "
        f"{_f(v['plm_general_uniform'])}" for d, v in P["category_ties_ok"].items())
        + "). In executed suites PLM is the pipeline's logic and PLM_uniform the "
        "pipeline_uniform variant's; Manifolds is the pipeline's kernel prior."
        + "".join(f" {name(d)}: Label fractions and Manifolds over its {r['n_objects']} objects "
                  f"(one prior per object, as the paper's 36 of 41), the PLM columns over its "
                  f"{r['n']} cases." for d, r in t["category"].items()
                  if r.get("n_objects") and r["n_objects"] != r.get("n"))]
    impossible = {d: v for d, v in t.get("impossible_evidence", {}).items() if v}
    L += ["", "Cases whose observations are impossible under a method's theory (a kernel prior "
          "certain of a category the observed parts rule out), counted as failures: "
          + ("; ".join(f"{name(d)}: " + ", ".join(f"{LABELS[m]} {n}" for m, n in v.items())
                       for d, v in impossible.items()) or "none") + "."]
    for d, r in t.get("per_category", {}).items():
        ms = ("manifolds", *LOGIC_METHODS)
        L += ["", f"{name(d)}, category accuracy per true category:", "",
              "| category | cases | " + " | ".join(LABELS[m] for m in ms) + " |",
              "|---|---|" + "---|" * len(ms)]
        for c, row in r.items():
            L.append(f"| {c} | {row['n']} | " + " | ".join(_f(row[m]) for m in ms) + " |")

    if t["task"]:
        L += ["", "## Task (paper Table \"task_plm_e0\" and Fig. \"task_plm\"; task inferred)", ""]
    for d, r in t["task"].items():
        ks = list(r["plm"])
        sizes = ", ".join(f"{k}: {v}" for k, v in r.get("gt_sizes", {}).items())
        L += [f"{name(d)} ({r['n']} scenarios" + (f"; ground-truth task sets of size {sizes}"
                                                  if sizes else "") + "):", "",
              "| method | " + " | ".join(ks) + " |", "|---|" + "---|" * len(ks)]
        for m in LOGIC_METHODS:
            L.append(f"| {LABELS[m]} | " + " | ".join(
                _both(r[m][k], P["task"].get(d, {}).get(m) if k == "E0" else None)
                for k in ks) + " |")
        L.append("")

    if t["pregrasp"]:
        L += ["## Pre-grasp (paper Table \"pregrasp_taskgiven_e0\" and Fig. "
              "\"pregrasp_taskgiven_plm\"; task given)", ""]
    for d, r in t["pregrasp"].items():
        if "plm" in r:
            ks = list(r["plm"])
            L += [f"{name(d)} ({r['n_pairs']} (scenario, ground-truth task) pairs; "
                  f"{r['no_grasp_pairs']} pairs without an acceptable grasp left out):", "",
                  "| method | " + " | ".join(ks) + " |", "|---|" + "---|" * len(ks)]
            for m in LOGIC_METHODS:
                L.append(f"| {LABELS[m]} | " + " | ".join(
                    _both(r[m][k], P["pregrasp"].get(d, {}).get(m) if k == "E0" else None)
                    for k in ks) + " |")
            L.append("")
        ex = [v for v in ("pipeline", "pipeline_uniform", "local") if v in r]
        if ex:
            L += [f"{name(d)}, executed: E_0 over runs whose planner found a grasp (part in Gt and "
                  "the object held through the lift); the logic's argmax part alone over all runs:",
                  "", "| variant | runs | valid | E0 executed | E0 logic |",
                  "|---|---|---|---|---|"]
            for v in ex:
                x = r[v]
                L.append(f"| {LABELS[v]} | {x['n_runs']} | {x['n_valid']} | "
                         f"{_both(x['E0_executed'], P['pregrasp'].get(d, {}).get(v))} | "
                         f"{_f(x['E0_logic'])} |")
            L.append("")

    if t["pipeline_vs_local"]:
        L += ["## Pipeline versus local shape only (paper Table \"pipeline\")", "",
              "Share of successful grasps (object held through the lift) whose P(grasp | local "
              "shape) is below the threshold, on the scenarios every variant ran. Local ranks all "
              "hypotheses by P(grasp | local shape) alone (`pipeline.scoring: "
              "!LocalOnly {}`).", ""]
    for d, r in t["pipeline_vs_local"].items():
        vs = [v for v in ("local", "pipeline", "pipeline_uniform") if v in r]
        p = P["pipeline_vs_local"].get(d, {})
        L += [f"{name(d)} ({r['n_scenarios']} scenarios):", "",
              "| measure | " + " | ".join(LABELS[v] for v in vs) + " |", "|---|" + "---|" * len(vs)]
        for th in THRESHOLDS:
            L.append(f"| lt {th} | " + " | ".join(_both(r[v][str(th)], p.get(v, {}).get(str(th)))
                                                 for v in vs) + " |")
        L.append("| held / runs | " + " | ".join(f"{r[v]['n_held']} ({_f(r[v]['held_rate'])} %)"
                                                  for v in vs) + " |")
        L.append("")

    if t["grasp_and_place"]:
        L += ["## Grasp and place per scene complexity (paper Table \"realRobotGlobalStats\")",
              "", "Pipeline variant; grasped and placed over the runs with a reachable pre-grasp, "
              "as the paper (a pass is placed when the receiver holds it).", "",
              "| objects | runs | reachable pre-grasps | grasped | placed | not placed, by "
              "reason |", "|---|---|---|---|---|---|"]
    for n, r in t["grasp_and_place"].items():
        p = P["grasp_and_place_pct"].get(n, {})
        L.append(f"| {n} ({', '.join(name(d) for d in r['datasets'])}) | {r['total']} "
                 f"({_f(P['grasp_and_place'].get(n, {}).get('total'))}) | {r['reachable']} "
                 f"{_both(r['reachable_pct'], p.get('reachable'))} | {r['grasped']} "
                 f"{_both(r['grasped_pct'], p.get('grasped'))} | {r['placed']} "
                 f"{_both(r['placed_pct'], p.get('placed'))} | "
                 + ", ".join(f"{k} {v}" for k, v in r["failures"].items()) + " |")

    if t.get("task_success"):
        L += ["", "## Task success in physics (ours)", "",
              "Each task executed and judged by physics (`task_outcome` of result.json: poured "
              "fraction ≥ 80 % with the container held, resting pose within 5 cm, resting on the "
              "surface, the receiver's hold), on the task suites "
              "(`scenarios/suites/tasks_*.yaml`). **Task success needs no written ground "
              "truth**: physics decides it. The executed "
              "E0 beside it is the set-valued measure (the grasp's part in the acceptable set "
              "written in `scenarios/suites/ground_truth.yaml`, the object held through the "
              "lift), over the runs with a planned grasp. Reachable: the planner found a grasp "
              "to execute. Train / held-out: the target's side of the object-wise split "
              "(`scenarios/suites/split.yaml`), over all runs. The full task suites: "
              f"`{TASK_SUITES_COMMAND}`.", "",
              "| task | variant | runs | success | reachable | success of reachable | train "
              "| held-out | E0 executed (runs) | task checks failed, by detail |",
              "|---|---|---|---|---|---|---|---|---|---|"]
        for task_name, v, r in _task_rows(t["task_success"]):
            sp = r["split"]
            L.append(f"| {task_name} | {LABELS[v]} | {r['n']} | **{_f(r['success'])}** | "
                     f"{r['n_reachable']} | {_f(r['success_reachable'])} | "
                     f"{_f(sp['train']['success'])} ({sp['train']['n']}) | "
                     f"{_f(sp['held_out']['success'])} ({sp['held_out']['n']}) | "
                     f"{_f(r['E0_executed'])} ({r['n_e0']}) | "
                     + "; ".join(f"{k} {n}" for k, n in r["failures"].items()) + " |")
        received = {v: r["received"] for task_name, v, r in _task_rows(t["task_success"])
                    if task_name == "pass" and r.get("received")}
        if received:
            L += ["", "pass, the part the receiver holds after a successful hand-over (measured "
                  "on the object's labelled mesh at its pads' contact; the success test does not "
                  "ask which): " + "; ".join(
                      f"{LABELS[v]} " + ", ".join(f"{part} {n}" for part, n in parts.items())
                      for v, parts in received.items()) + "."]
        diffs = {k: v.get("pipeline_minus_local") for k, v in t["task_success"].items()
                 if v.get("pipeline_minus_local") is not None}
        if diffs:
            L += ["", "Pipeline − Local, task success over all runs [points]: " + ", ".join(
                f"{k} {_f(v)}" for k, v in diffs.items()) + "."]

    if t.get("outcomes"):
        L += ["", "## Outcomes of the executed runs (ours)", "",
              "Over all runs (the paper's table above counts grasped and placed over the runs "
              "with a reachable pre-grasp): grasped = the object was in the hand, lifted = held "
              "through the lift, placed = put down as the task asks, or handed over to the "
              "receiver for a pass.", "",
              "| dataset | variant | runs | grasped | lifted | placed | not placed, by reason | "
              "median wall time [s] |", "|---|---|---|---|---|---|---|---|"]
        for d, by_variant in t["outcomes"].items():
            for v, r in by_variant.items():
                L.append(f"| {name(d)} | {LABELS[v]} | {r['n']} | {_f(r['grasped'])} | "
                         f"{_f(r['lifted'])} | {_f(r['placed'])} | "
                         + ", ".join(f"{k} {n}" for k, n in r["failures"].items())
                         + f" | {_f(r['wall_seconds_median'])} |")
        for d, by_variant in t["outcomes"].items():
            if d not in OURS or "pipeline" not in by_variant:
                continue
            statuses = ("placed", "lifted", "grasped", "failed", "error")
            L += ["", f"{name(d)}, Pipeline, outcomes per category:", "",
                  "| category | runs | " + " | ".join(statuses) + " |",
                  "|---|---|" + "---|" * len(statuses)]
            for c, row in by_variant["pipeline"]["per_category"].items():
                L.append(f"| {c} | {row['n']} | " + " | ".join(str(row.get(k, 0))
                                                             for k in statuses) + " |")

    a = t["ablations"]
    if not a["top_category"]:
        return _text(L)
    L += ["", "## Ablation: the top category only versus the full prior (PLM)", "",
          "| dataset | category full | top only | task E0 full | top only | pre-grasp E0 full | "
          "top only |", "|---|---|---|---|---|---|---|"]
    for d, r in a["top_category"].items():
        f, o = r["full_prior"], r["top_category"]
        L.append(f"| {name(d)} | {_f(f['category'])} | {_f(o['category'])} | {_f(f['task_E0'])} | "
                 f"{_both(o['task_E0'], P['top_category_task'].get(d))} | "
                 f"{_f(f['pregrasp_E0'])} | "
                 f"{_both(o['pregrasp_E0'], P['top_category_pregrasp'].get(d))} |")
    L += ["", "## Ablation: mutually exclusive versus not (PLM)", "",
          "| dataset | category excl. | not | task E0 excl. | not | pre-grasp E0 excl. | not |",
          "|---|---|---|---|---|---|---|"]
    for d, r in a["exclusive"].items():
        e, n = r["exclusive"], r["nonexclusive"]
        L.append(f"| {name(d)} | {_f(e['category'])} | {_f(n['category'])} | {_f(e['task_E0'])} "
                 f"| {_f(n['task_E0'])} | {_f(e['pregrasp_E0'])} | {_f(n['pregrasp_E0'])} |")
    md, pm = a["exclusive_mean_difference"], P["exclusive_minus_nonexclusive"]
    L += ["", f"Mean difference exclusive − not over the datasets: category "
          f"{_both(md['category'], pm['category'])}, task {_both(md['task_E0'], pm['task'])}, "
          f"pre-grasp {_both(md['pregrasp_E0'], pm['pregrasp'])} points."]
    if a.get("interior"):
        L += ["", "## Ablation: the interior observation (ours) versus the paper's observations "
              "(PLM)", "", "`interior_seen`: the camera saw the object's inside through a wide "
              "opening "
              "(tg_drake/perception/pose.py `interior_seen`; perfect on S_SYN: an open container "
              "not upside down); the theory rules out cans and bottles "
              "(rules/category_*.pl). The paper has no such observation.", "",
              "| dataset | category with | paper's only | task E0 with | paper's only | "
              "pre-grasp E0 with | paper's only |", "|---|---|---|---|---|---|---|"]
        for d, r in a["interior"].items():
            w, o = r["with"], r["without"]
            L.append(f"| {name(d)} | {_f(w['category'])} | {_f(o['category'])} | "
                     f"{_f(w['task_E0'])} | {_f(o['task_E0'])} | {_f(w['pregrasp_E0'])} | "
                     f"{_f(o['pregrasp_E0'])} |")
        L.append("")
    return _text(L)
