"""tg_drake.report.write: result.json first, the pictures after; a picture that fails is a
warning, never a lost result."""

from __future__ import annotations

import json

import numpy as np

from tg_drake.report import Pictures, Stages, write
from tg_drake.types import SceneDescription


def test_a_failing_picture_is_a_warning_and_the_result_is_kept(tmp_path):
    result = {"scenario": "x", "outcome": {"status": "placed", "reason": "", "detail": ""},
              "grasp": {"part": "middle", "score": 0.5, "p_part": 0.5, "p_local": 1.0}}
    # An object that is not an ObjectDescription: parts.png and grasp.png cannot be drawn.
    broken = SceneDescription(objects=[object()], X_WT=np.eye(4), target=0)
    pictures = Pictures(Stages(scene=broken, rgb=np.zeros((4, 6, 3), np.uint8)), X_WG=np.eye(4))
    warnings = write(tmp_path, result, pictures)
    written = json.loads((tmp_path / "result.json").read_text())
    assert written.pop("warnings") == warnings
    assert written == {k: v for k, v in result.items() if k != "warnings"}
    assert (tmp_path / "camera.png").is_file()
    assert sorted(w.split()[0] for w in warnings) == ["grasp.png", "parts.png"]
    assert not (tmp_path / "parts.png").exists()


def test_the_missing_pictures_are_named_in_the_result(tmp_path):
    result = {"scenario": "x", "outcome": {"status": "placed", "reason": "", "detail": ""}}
    broken = SceneDescription(objects=[object()], X_WT=np.eye(4), target=0)
    write(tmp_path, result, Pictures(Stages(scene=broken)))
    written = json.loads((tmp_path / "result.json").read_text())
    assert [w.split()[0] for w in written["warnings"]] == ["parts.png"]


def test_the_grasp_picture_title_and_the_summary_place_p_hold_as_the_stage_uses_it():
    from tg_drake.report import _grasp_title
    grasp = {"part": "middle", "score": 0.74, "p_part": 0.88, "p_local": 0.84, "p_hold": 0.86}
    for ranked, shown in ((False, "; P(hold) 0.86, not ranked by"), (True, " × P(hold) 0.86")):
        result = {"grasp": grasp, "outcome": {"status": "placed"},
                  "config": {"pipeline": {"feasibility": {"rank_by_hold": ranked}}}}
        assert shown in _grasp_title(result)


def test_the_summary_says_when_the_object_was_reseated_at_its_release():
    from tg_drake.report import summary
    outcome = {"status": "placed", "reason": "", "detail": "1.0 cm from the target",
               "unreachable_parts": [], "requeries": 0}
    result = {"scenario": "x", "timings": {"total": 1.0}, "outcome": outcome}
    assert "release" not in summary(result)
    result["outcome"] = dict(outcome, reseats=1)
    line = next(x for x in summary(result).splitlines() if x.startswith("release"))
    assert "re-seated 1 time " in line
