"""Issue 20's generalization table (tg_drake.evaluation.generalization, tools/generalization.py):
records grouped by the side of the split and by generated / scan-like, each measure computed by
tg_drake.evaluation.tables."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

from tg_drake.evaluation.generalization import NOT_MEASURED, compute, markdown
from tg_drake.evaluation.split import load_split
from tg_drake.types import CATEGORIES, PART_LABELS, TASKS

REPO = Path(__file__).resolve().parents[2]


def onehot(names, name):
    return [float(n == name) for n in names]


def perceived(obj, category, setting, *, right: bool, pose_ok: bool = True):
    """A perceived record whose PLM names the category (right) or a wrong one, and the handle."""
    guess = category if right else ("bowl" if category != "bowl" else "cup")
    return {"job": f"g/{obj}_{setting}", "kind": "perceived", "object": obj, "pose": "upright",
            "dataset": {"semi": "real_semi", "real": "real"}[setting], "setting": setting,
            "truth": {"category": category, "tasks": ["pass"], "parts": {"pass": ["handle"]}},
            "detection": {"pose_ok": pose_ok, "parts_ok": True},
            "priors": {"label_fractions": onehot(CATEGORIES, guess),
                       "manifolds": onehot(CATEGORIES, guess)},
            "methods": {"plm": {"category": onehot(CATEGORIES, guess),
                                "task": onehot(TASKS, "pass"),
                                "part": {"pass": onehot(PART_LABELS, "handle" if right
                                                        else "top")}}}}


def executed(obj, category, status):
    return {"job": f"x/{obj}", "kind": "executed", "dataset": "grasp", "variant": "pipeline",
            "object": obj, "pose": "upright", "task_given": "pass", "n_objects": 1,
            "truth": {"category": category, "tasks": ["pass"], "parts": {"pass": ["handle"]}},
            "grasp": {"part": "handle"}, "outcome": {"status": status}}


def records():
    rs = []
    for setting in ("semi", "real"):
        rs += [perceived("cup_01", "cup", setting, right=True),
               perceived("cup_b02", "cup", setting, right=True),
               perceived("cup_04", "cup", setting, right=False, pose_ok=False),
               perceived("cup_b03", "cup", setting, right=True),
               perceived("cup_04_scan", "cup", setting, right=False)]
    return rs + [perceived("mug_x", "cup", "real", right=True),
                 executed("pot_01", "pot", "placed"), executed("pot_04", "pot", "grasped")]


def test_measures_are_grouped_by_the_side_of_the_split_and_the_source():
    t = compute(records(), load_split())
    g = t["groups"]
    assert g["train/generated"]["category_plm"] == 100.0
    assert g["held_out/generated"]["category_plm"] == 50.0  # cup_04 wrong, cup_b03 right
    assert g["held_out/generated"]["pose"] == 50.0
    assert g["train/generated"]["pose"] == 100.0
    assert g["held_out/scan_like"]["category_plm"] == 0.0
    assert g["train/scan_like"]["category_plm"] is None  # no records: not measured
    assert g["held_out/generated"]["pregrasp_e0_semi"] == 50.0
    assert t["held_out_minus_train"]["generated"]["category_plm"] == -50.0
    assert t["by_set"]["held_out/generated"]["a"]["category_plm"] == 0.0
    assert t["by_set"]["held_out/generated"]["b"]["category_plm"] == 100.0
    assert t["per_category"]["train/generated"]["cup"]["category_plm"] == 100.0
    assert t["per_category"]["train/generated"]["knife"]["category_plm"] is None
    assert t["unassigned_objects"] == ["mug_x"]


def test_executed_rows_grasped_placed_and_e0():
    t = compute(records(), load_split())
    train, held = t["groups"]["train/generated"], t["groups"]["held_out/generated"]
    assert (train["grasped"], train["placed"], train["executed_e0"]) == (100.0, 100.0, 100.0)
    # grasped but dropped before the lift: grasped, not placed, not an E0 success
    assert (held["grasped"], held["placed"], held["executed_e0"]) == (100.0, 0.0, 0.0)


def test_markdown_says_what_is_not_measured_and_how_to_fill_it():
    text = markdown(compute(records(), load_split()), command="CMD-HERE")
    assert "CMD-HERE" in text and NOT_MEASURED in text and "## Protocol" in text
    row = next(line for line in text.splitlines() if line.startswith("| category, PLM argmax"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1:5] == ["100.0", "50.0", NOT_MEASURED, "0.0"]
    assert cells[5] == "-50.0" and cells[6:8] == ["55.9", "70.8"]


def test_the_tool_writes_json_and_markdown(tmp_path):
    spec = importlib.util.spec_from_file_location("generalization_tool",
                                                  REPO / "tools" / "generalization.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    results = tmp_path / "results.jsonl"
    results.write_text("".join(json.dumps(r) + "\n" for r in records()))
    assert tool.main([str(results), "--out", str(tmp_path / "gen")]) == 0
    t = json.loads((tmp_path / "gen.json").read_text())
    assert t["groups"]["train/generated"]["category_plm"] == 100.0
    assert "tools/generalization.py" in t["command"]
    assert (tmp_path / "gen.md").read_text().startswith("# Generalization")
    # without records: the skeleton, every cell not measured
    assert tool.main(["--out", str(tmp_path / "empty")]) == 0
    empty = json.loads((tmp_path / "empty.json").read_text())
    assert all(v is None for g in empty["groups"].values() for k, v in g.items()
               if not k.startswith("n_"))


@pytest.mark.parametrize("obj,side", [("knife_04", "held_out"), ("knife_b01", "train")])
def test_split_sides_used_by_the_table(obj, side):
    assert load_split().role(obj) == side
