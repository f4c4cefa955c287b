"""Two sweeps of the same suites compared case by case: what a change did to every case.

A table says a rate moved; this says which cases moved and why. Records are matched by case key
and dataset (a perceived case has one record per setting). Measured per record:

- perceived and synthetic: the PLM's category argmax is the truth (ties fail, as the tables), and
  for perceived ones the pose perception found is the true one;
- executed: the object was delivered (`tables.delivered`: placed, or handed over for a pass), and
  the part grasped is in the acceptable set (E0; no grasp = not counted).

`compare(base, now)` gives, per (suite, dataset, variant) and measure, the four counts (kept,
gained, lost, neither), and the executed cases whose delivery changed with both outcomes; each lost
one carries a class of why (`failure_class`), so that a regression reads as a list of mechanisms.
`markdown(...)` writes it as a page; `tools/compare_runs.py` is the command.
"""

from __future__ import annotations

import re
from collections import Counter, defaultdict

from tg_drake.evaluation.tables import delivered, top_set
from tg_drake.types import CATEGORIES

MEASURES = ("category", "pose", "delivered", "e0")


def _key(r) -> tuple:
    return r["job"], r.get("dataset", "")


def _category_ok(r) -> bool | None:
    p = ((r.get("methods") or {}).get("plm") or {}).get("category")
    if p is None:  # an executed run: the pipeline's own category distribution
        dist = r.get("category")
        if not isinstance(dist, dict) or not dist:
            return None
        p = [dist.get(c, 0.0) for c in CATEGORIES]
    truth = (r.get("truth") or {}).get("category")
    return truth in CATEGORIES and top_set(p) == {CATEGORIES.index(truth)}


def _pose_ok(r) -> bool | None:
    if r.get("kind") == "perceived":
        return (r.get("detection") or {}).get("pose_ok")
    if r.get("kind") == "executed" and isinstance(r.get("perception"), dict):
        return r["perception"].get("pose") == r.get("pose")
    return None


def _e0(r) -> bool | None:
    part = (r.get("grasp") or {}).get("part")
    if not part:
        return None
    return part in ((r.get("truth") or {}).get("parts") or {}).get(r.get("task_given"), [])


def measures(r) -> dict:
    """The record's measures (None where a measure does not apply)."""
    out = {"category": _category_ok(r), "pose": _pose_ok(r)}
    if r.get("kind") == "executed":
        out["delivered"] = delivered(r) if "error" not in r else False
        out["e0"] = _e0(r)
    return out


def failure_class(r) -> str:
    """Why an executed run did not deliver, as a mechanism rather than an object: the planning
    failure's step, the supervisor's reason, the hand-over's check."""
    if "error" in r:
        return "error"
    out = r.get("outcome") or {}
    detail = out.get("detail", "")
    for step in ("retreat trajectory", "pre-place pose", "place pose", "carry trajectory",
                 "descend trajectory", "pour pose", "tilted pose", "return trajectory"):
        if step in detail:
            return f"unreachable: {step}"
    if "logic rule" in detail:
        return "unreachable: the logic's gate"
    if out.get("reason") and out["reason"] != "none":
        return out["reason"]
    task = out.get("task_outcome") or {}
    if task.get("task") == "pass":
        why = re.sub(r"[-\d.]+ ?mm", "N mm", task.get("detail", ""))
        return "not handed over: " + why.split(":")[0]
    return out.get("status", "failed")


def compare(base: list[dict], now: list[dict]) -> dict:
    """Case-by-case comparison (module docstring): {"n": counts of records, "measures": {group:
    {measure: {kept, gained, lost, neither}}}, "changed": [executed cases whose delivery
    changed], "lost_by_class": {group: {class: n}}}."""
    b = {_key(r): r for r in base}
    n = {_key(r): r for r in now}
    common = sorted(set(b) & set(n))
    table: dict = defaultdict(lambda: defaultdict(Counter))
    changed, lost = [], defaultdict(Counter)
    for key in common:
        rb, rn = b[key], n[key]
        group = f"{rn.get('suite')} / {rn.get('dataset')}" + (
            f" / {rn['variant']}" if rn.get("variant") else "")
        mb, mn = measures(rb), measures(rn)
        for m in MEASURES:
            if mb.get(m) is None or mn.get(m) is None:
                continue
            word = {(True, True): "kept", (False, True): "gained", (True, False): "lost",
                    (False, False): "neither"}[(bool(mb[m]), bool(mn[m]))]
            table[group][m][word] += 1
        if "delivered" in mb and mb["delivered"] != mn["delivered"]:
            entry = {"job": key[0], "group": group, "base": _outcome_text(rb),
                     "now": _outcome_text(rn), "lost": bool(mb["delivered"])}
            if entry["lost"]:
                entry["class"] = failure_class(rn)
                lost[group][entry["class"]] += 1
            changed.append(entry)
    return {"n": {"base": len(b), "now": len(n), "common": len(common)},
            "measures": {g: {m: dict(c) for m, c in ms.items()} for g, ms in table.items()},
            "changed": changed,
            "lost_by_class": {g: dict(c.most_common()) for g, c in lost.items()}}


def _outcome_text(r) -> str:
    if "error" in r:
        return f"error: {r['error'][:60]}"
    out = r.get("outcome") or {}
    part = (r.get("grasp") or {}).get("part")
    return (f"{out.get('status')}{'/' + out['reason'] if out.get('reason') else ''}"
            f"{' (' + part + ')' if part else ''}: {out.get('detail', '')[:90]}")


def markdown(result: dict, *, base_name: str, now_name: str, command: str = "") -> str:
    """The comparison as a Markdown page."""
    L = [f"# {now_name} against {base_name}, case by case", ""]
    if command:
        L += [f"Command: `{command}`", ""]
    c = result["n"]
    L += [f"Records: {c['base']} ({base_name}), {c['now']} ({now_name}), {c['common']} in both.",
          "", "Per suite, dataset and variant: kept (right in both), gained, lost, neither. "
          "category: the PLM's argmax (the pipeline's, for executed runs); pose: perception's; "
          "delivered: placed, or handed over for a pass; e0: the grasped part acceptable.", "",
          "| suite / dataset / variant | measure | kept | gained | lost | neither |",
          "|---|---|---|---|---|---|"]
    for group, ms in result["measures"].items():
        for m in MEASURES:
            if m in ms:
                k = ms[m]
                L.append(f"| {group} | {m} | {k.get('kept', 0)} | {k.get('gained', 0)} | "
                         f"{k.get('lost', 0)} | {k.get('neither', 0)} |")
    if result["lost_by_class"]:
        L += ["", "## Deliveries lost, by class", "",
              "| suite / dataset / variant | class | runs |", "|---|---|---|"]
        for group, classes in result["lost_by_class"].items():
            L += [f"| {group} | {cls} | {k} |" for cls, k in classes.items()]
    if result["changed"]:
        L += ["", "## Every executed case whose delivery changed", "",
              f"| case | {base_name} | {now_name} |", "|---|---|---|"]
        for e in sorted(result["changed"], key=lambda e: (not e["lost"], e["job"])):
            L.append(f"| {'lost' if e['lost'] else 'gained'}: `{e['job']}` | "
                     f"{e['base'].replace('|', '/')} | {e['now'].replace('|', '/')} |")
    return "\n".join(L) + "\n"
