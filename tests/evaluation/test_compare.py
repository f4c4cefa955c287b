"""Two sweeps compared case by case (tg_drake.evaluation.compare), on records written by hand."""

from tg_drake.evaluation.compare import compare, failure_class, markdown
from tg_drake.types import CATEGORIES


def executed(job, status, *, reason="", detail="", part="middle", task="p&pOn", success=None):
    task_outcome = ({"task": task, "success": success, "measure": {}, "detail": detail}
                    if success is not None else None)
    return {"job": job, "suite": "s", "kind": "executed", "dataset": "grasp",
            "variant": "pipeline", "task_given": task, "pose": "upright",
            "truth": {"category": "cup", "parts": {task: ["middle"]}},
            "category": {"cup": 0.9, "glass": 0.1},
            "perception": {"pose": "upright"}, "grasp": {"part": part} if part else None,
            "outcome": {"status": status, "reason": reason, "detail": detail,
                        "task_outcome": task_outcome}}


def perceived(job, category, pose_ok):
    p = [0.0] * len(CATEGORIES)
    p[CATEGORIES.index(category)] = 1.0
    return {"job": job, "suite": "r", "kind": "perceived", "dataset": "real",
            "truth": {"category": "cup"}, "methods": {"plm": {"category": p}},
            "detection": {"pose_ok": pose_ok}}


def test_cases_are_matched_by_key_and_each_change_is_counted_and_classed():
    base = [executed("s/a", "placed"), executed("s/b", "placed"), executed("s/c", "failed",
            reason="missed", part=None), perceived("r/x", "cup", True)]
    now = [executed("s/a", "placed"),
           executed("s/b", "failed", reason="unreachable", part=None,
                    detail="the object can be picked but not placed at (0.750, -0.300) m: "
                           "retreat trajectory: trajectory optimisation failed"),
           executed("s/c", "lifted", task="p&pOn", part="handle"), perceived("r/x", "glass", False)]
    now[2]["outcome"]["status"] = "placed"
    result = compare(base, now)
    assert result["n"] == {"base": 4, "now": 4, "common": 4}
    grasp = result["measures"]["s / grasp / pipeline"]
    assert grasp["delivered"] == {"kept": 1, "lost": 1, "gained": 1}
    assert grasp["e0"] == {"kept": 1}  # b and c have no grasp on one side: not counted
    assert result["measures"]["r / real"] == {"category": {"lost": 1}, "pose": {"lost": 1}}
    assert result["lost_by_class"] == {"s / grasp / pipeline": {
        "unreachable: retreat trajectory": 1}}
    lost = [e for e in result["changed"] if e["lost"]]
    assert [e["job"] for e in lost] == ["s/b"]
    page = markdown(result, base_name="old", now_name="new")
    assert "| lost: `s/b` | placed (middle): " in page
    assert "| s / grasp / pipeline | unreachable: retreat trajectory | 1 |" in page


def test_a_pass_not_taken_is_classed_by_the_receivers_check():
    r = executed("s/p", "lifted", task="pass", success=False,
                 detail="its height changed 43 mm while the receiver held it (> 10 mm)")
    assert failure_class(r) == ("not handed over: its height changed N mm while the receiver "
                                "held it (> N mm)")
    r = executed("s/q", "lifted", task="pass", success=True)
    assert compare([r], [r])["measures"]["s / grasp / pipeline"]["delivered"] == {"kept": 1}
