"""Issue 21's task suites (scenarios/suites/tasks_*.yaml): each loads and expands into cases that
give the task what it needs in the scene (the suite's `task_scene`), in the four variants, tagged
with the split; the random-part variant's seed; and the task-success table on synthetic records."""

import textwrap
from pathlib import Path

import pytest

from tg_drake.errors import ScenarioError
from tg_drake.evaluation.jobs import scenario_of, scoring_of
from tg_drake.evaluation.suite import load_suite
from tg_drake.evaluation.tables import compute, markdown, task_success_text
from tg_drake.scenario import DgiScorer, LocalOnly, RandomPart

SUITES = Path(__file__).resolve().parents[2] / "scenarios" / "suites"
VARIANTS = ["pipeline", "pipeline_uniform", "local", "random_part"]
# suite → (its task, the start poses that make the task non-trivial, or None: any)
TASK_SUITES = {"tasks_pour_out": ("pourOut", None), "tasks_pour_in": ("pourIn", None),
               "tasks_on": ("p&pOn", None), "tasks_pass": ("pass", None),
               "tasks_upright": ("p&pInUpright", {"sideways", "upsidedown"}),
               "tasks_sideways": ("p&pInSideways", {"upright", "upsidedown"}),
               "tasks_upsidedown": ("p&pInUpsidedown", {"upright", "sideways"})}


@pytest.mark.slow  # 45 s: every case's scene is validated (the spheres' sites in each cavity)
@pytest.mark.parametrize("name", sorted(TASK_SUITES))
def test_a_task_suite_expands_into_its_task_with_what_the_scene_needs(name):
    suite, cases = load_suite(SUITES / f"{name}.yaml")
    task, poses = TASK_SUITES[name]
    assert suite.dataset == "tasks" and suite.variants == VARIANTS
    assert {c.task for c in cases} == {task}
    scenarios = {c.key.split("@")[0] for c in cases}
    assert len(cases) == 4 * len(scenarios)  # every scenario in the four variants
    assert {c.meta()["split"] for c in cases} == {"train", "held_out"}  # both sets' sides
    assert any("_b0" in c.target_placement.id for c in cases)  # set b's objects too
    for c in cases:
        assert task in c.truth.tasks  # only objects that afford the task
        if poses is not None:
            assert c.target_placement.pose in poses
    s = scenario_of(cases[0])
    if task == "pourOut":
        assert s.contents.model == "spheres" and cases[0].target_placement.containment == "full"
        assert s.task.pour_into in [p.instance_name for p in s.objects]
    if task == "pourIn":
        assert s.dispenser is not None and s.simulation_duration == 30.0
    if task == "p&pOn":
        assert s.task.place_on == s.surfaces[0].name == "shelf"
    if task in ("pass", "p&pInUpright"):
        assert not s.surfaces and s.dispenser is None and len(s.objects) == 1


SMALL = """
    name: small_tasks
    kind: executed
    dataset: tasks
    variants: [pipeline, local, random_part]
    ground_truth: {gt}
    generator: {{objects: [cup_01, cup_04], poses: [upright], containments: [full],
                tasks: [pourOut], xy: [0.0, 0.05]}}
    task_scene:
      objects: [{{id: bowl_01, name: into, pose: upright, xy: [-0.05, -0.25]}}]
      pour_into: {into}
      contents: {{model: spheres}}
      simulation_duration: 25.0
"""


def _small(tmp_path, into="into", extra=""):
    path = tmp_path / "small.yaml"
    path.write_text(textwrap.dedent(SMALL.format(gt=SUITES / "ground_truth.yaml", into=into))
                    + extra)
    return path


def test_the_task_scene_reaches_every_case_and_random_part_is_seeded_by_the_case(tmp_path):
    suite, cases = load_suite(_small(tmp_path))
    assert [c.key for c in cases][:3] == [f"small_tasks/cup_01_upright_full_pourOut@{v}"
                                           for v in ("pipeline", "local", "random_part")]
    assert [c.meta()["split"] for c in cases[::3]] == ["train", "held_out"]
    s = scenario_of(cases[2])
    assert [p.instance_name for p in s.objects] == ["cup_01", "into"]
    assert (s.task.pour_into, s.contents.model, s.simulation_duration) == ("into", "spheres", 25.0)
    assert isinstance(scoring_of(cases[0]), DgiScorer)
    assert isinstance(scoring_of(cases[1]), LocalOnly)
    seed = scoring_of(cases[2]).seed
    assert isinstance(scoring_of(cases[2]), RandomPart)
    assert scoring_of(load_suite(_small(tmp_path))[1][2]).seed == seed  # the same case, again
    assert scoring_of(cases[5]).seed != seed  # another scenario draws with another seed
    assert cases[0].scenario().objects[0] is not cases[0].objects[0]  # the case is not changed


def test_bad_task_scenes_are_named_with_the_case(tmp_path):
    with pytest.raises(ScenarioError, match=r"task_scene.*case small_tasks/cup_01_upright_full_"
                                            r"pourOut: unknown object to pour into 'bowl'"):
        load_suite(_small(tmp_path, into="bowl"))
    text = (SUITES / "tiny.yaml").read_text() + "task_scene: {pour_into: x}\n"
    (tmp_path / "tiny.yaml").write_text(text.replace("ground_truth.yaml",
                                                     str(SUITES / "ground_truth.yaml")))
    with pytest.raises(ScenarioError, match="a task scene is for executed suites"):
        load_suite(tmp_path / "tiny.yaml")


def _record(variant, split, success, *, grasp_part="middle", status="placed", task="pourOut"):
    return {"job": f"tasks_pour_out/x_{split}_{success}@{variant}", "kind": "executed",
            "dataset": "tasks", "variant": variant, "split": split, "task_given": task,
            "n_objects": 1, "object": "x", "pose": "upright", "object_parts": ["middle", "top"],
            "truth": {"category": "cup", "tasks": [task], "parts": {task: ["middle"]}},
            "grasp": {"part": grasp_part} if grasp_part else None,
            "outcome": {"status": status, "reason": "" if success else "slipped",
                        "task_outcome": {"task": task, "success": success, "measure": {},
                                         "detail": "" if success else "3 of 10 in bowl"}},
            "timings": {"total": 10.0}}


def test_task_success_per_task_and_variant_beside_the_executed_e0():
    records = [_record("pipeline", "train", True), _record("pipeline", "held_out", True),
               _record("pipeline", "held_out", False, grasp_part="top"),
               _record("local", "train", False, grasp_part="top"),
               _record("local", "held_out", False, grasp_part=None, status="failed"),
               {**_record("local", "train", True), "error": "crashed"},
               _record("random_part", "train", True, task="p&pOn")]
    t = compute(records)["task_success"]
    p, lo = t["pourOut"]["pipeline"], t["pourOut"]["local"]
    assert (p["n"], p["success"], p["n_reachable"], p["success_reachable"]) == (3, 66.67, 3,
                                                                                 66.67)
    assert p["split"]["train"]["success"] == 100.0 and p["split"]["held_out"]["success"] == 50.0
    assert p["E0_executed"] == 66.67  # the top grasp is not an acceptable part for pouring out
    assert (lo["n"], lo["success"], lo["n_reachable"], lo["success_reachable"]) == (3, 0.0, 2,
                                                                                    0.0)
    assert lo["failures"] == {"3 of 10 in bowl": 1, "run failed: slipped": 1, "crashed": 1}
    assert t["pourOut"]["pipeline_minus_local"] == 66.67
    assert list(t["p&pOn"]) == ["random_part"]
    md = markdown(compute(records), command="tg-drake eval x")
    assert "## Task success in physics (ours)" in md and "needs no written ground" in md
    assert "| pourOut | Pipeline | 3 | **66.67** | 3 | 66.67 | 100.00 (1) | 50.00 (2) |" in md
    assert "Random part" in task_success_text(compute(records))
    assert compute([r for r in records if r["variant"] == "x"])["task_success"] == {}


def test_the_part_the_receiver_holds_is_counted_over_successful_passes():
    def passed(variant, part, success=True):
        r = _record(variant, "train", success, grasp_part="usable_area", status="lifted",
                    task="pass")
        r["outcome"]["task_outcome"]["measure"] = {"received_part": part}
        return r

    records = [passed("pipeline", "handle"), passed("pipeline", "handle"),
               passed("local", "usable_area"), passed("local", "handle", success=False),
               passed("local", "")]
    t = compute(records)["task_success"]["pass"]
    assert t["pipeline"]["received"] == {"handle": 2}
    assert t["local"]["received"] == {"usable_area": 1, "unknown": 1}  # the failure not counted
    md = markdown(compute(records), command="tg-drake eval x")
    assert "the part the receiver holds after a successful hand-over" in md
    assert "Pipeline handle 2; Local usable_area 1, unknown 1." in md
