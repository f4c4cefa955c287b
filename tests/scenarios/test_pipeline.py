"""The whole pipeline on named scenarios: perceive, reason, score, plan, grasp, place.

The default scenario runs in the default test run (its run is shared with the other scenario
tests); the others are marked slow (`make test-slow`).
"""

import json
from pathlib import Path

import numpy as np
import pytest

from tg_drake.report import summary
from tg_drake.run import run_scenario
from tg_drake.scenario import load_scenario, look_at
from tg_drake.systems.supervisor import FAILURE_REASONS, OUTCOME_STATUSES
from tg_drake.types import CATEGORIES, PART_LABELS, POSES, TASKS

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def run(name: str, **changes) -> dict:
    scenario = load_scenario(SCENARIOS / f"{name}.yaml")
    for key, value in changes.items():
        setattr(scenario, key, value)
    result = run_scenario(scenario, scenario_path=name)
    json.dumps(result)  # result.json must serialise
    return result


def check_result_keys(result: dict) -> None:
    """result.json holds the keys docs/design.md documents, with values of the documented kinds."""
    for key in ("scenario", "perception", "outcome", "timings"):
        assert key in result, key
    outcome = result["outcome"]
    assert outcome["status"] in OUTCOME_STATUSES
    if outcome["status"] == "failed":
        assert outcome["reason"] in FAILURE_REASONS
    if result["perception"].get("pose") is not None:
        assert result["perception"]["pose"] in POSES
        assert set(result["perception"]["parts"]) <= set(PART_LABELS)
    for key, names in (("category_prior", CATEGORIES), ("category", CATEGORIES),
                       ("task", TASKS), ("part", PART_LABELS)):
        if key in result:
            assert set(result[key]) <= set(names)
            # Distributions sum to 1 (1e-5: rounded to 6 decimals per entry in result.json).
            assert sum(result[key].values()) == pytest.approx(1.0, abs=1e-5), key
    if "grasp" in result:
        g = result["grasp"]
        assert len(g["xyz"]) == 3 and len(g["rpy"]) == 3
        assert g["part"] in PART_LABELS
        # The executed pose's score: P(part | task) · P(grasp | local shape), times P(hold) when
        # the feasibility stage ranks by it (P(hold) is reported either way).
        ranked_by_hold = result["config"]["pipeline"]["feasibility"]["rank_by_hold"]
        p_hold = g["p_hold"] if ranked_by_hold and g.get("p_hold") is not None else 1.0
        assert g["score"] == pytest.approx(g["p_part"] * g["p_local"] * p_hold, rel=1e-6)
        # Its contact mechanics on the perceived points: a pose the stage let through is not
        # one the grip squeezes out.
        h = g["hold"]
        assert h["squeeze"] is not None and 0.0 <= h["squeeze"] < 1.0
        assert h["width_mm"] > 0 and h["mass_kg"] > 0 and h["patch_area_mm2"] > 0
    assert all(v >= 0 for v in result["timings"].values())


def test_default_scenario_passes_the_cup_by_its_middle(cached_run):
    result = cached_run(SCENARIOS / "default.yaml")
    check_result_keys(result)
    # The paper's Fig. 1 cup: cup is the most likely category, pass takes it by the middle.
    assert max(result["category"], key=result["category"].get) == "cup"
    assert max(result["part"], key=result["part"].get) == "middle"
    assert result["grasp"]["part"] == "middle"
    # A pass: handed over to the receiver, which holds it alone (the robot's outcome: lifted).
    assert result["outcome"]["status"] == "lifted", result["outcome"]
    assert result["outcome"]["detail"].startswith("handed over"), result["outcome"]
    assert result["task_outcome"]["success"], result["task_outcome"]
    # The part the receiver holds, measured on the cup's labelled mesh: one the robot left free.
    m = result["task_outcome"]["measure"]
    assert m["received_part"] in ("top", "bottom", "handle"), m
    assert f"by its {m['received_part']}" in result["task_outcome"]["detail"]
    assert "cup" in summary(result) and "handed over" in summary(result)
    # The stage ranks by P(hold): a factor of the executed pose's score, and the summary says so.
    assert result["config"]["pipeline"]["feasibility"]["rank_by_hold"]
    grasp_line = next(line for line in summary(result).splitlines() if line.startswith("grasp"))
    assert "× P(hold)" in grasp_line and "not ranked by" not in grasp_line
    assert result["grasp"]["p_hold"] >= result["config"]["pipeline"]["feasibility"]["min_p_hold"]
    # What the run used is what it reports: planning done, no collision evidence, and the full
    # resolved configuration (the supervisor's settings included).
    assert result["planning"]["status"] == "done"
    assert 0 < result["planning"]["ik_solves"] < result["config"]["pipeline"]["planner"][
        "max_ik_solves"]  # the planner's effort, well within its budget
    assert result["collisions"] == result["outcome"]["unreachable_parts"] == []
    assert result["config"]["pipeline"]["supervisor"]["max_requeries"] == 3
    assert result["config"]["objects"][0]["id"] == "cup_01"


@pytest.mark.slow
def test_hammer_for_pass_is_taken_by_the_usable_area():
    result = run("hammer_pass")
    check_result_keys(result)
    assert result["perception"]["pose"] == "sideways"
    assert max(result["part"], key=result["part"].get) == "usable_area"
    assert result["grasp"]["part"] == "usable_area"
    assert result["outcome"]["status"] in ("lifted", "placed"), result["outcome"]


@pytest.mark.slow
def test_object_out_of_reach_fails_as_unreachable():
    result = run("out_of_reach")
    check_result_keys(result)
    assert result["outcome"]["status"] == "failed"
    assert result["outcome"]["reason"] == "unreachable"
    # The closed loop asked the logic again with the unreachable parts as collision evidence.
    assert result["outcome"]["unreachable_parts"]
    assert result["collisions"] == result["outcome"]["unreachable_parts"]


@pytest.mark.slow
def test_hidden_target_fails_with_a_perception_reason():
    scenario = load_scenario(SCENARIOS / "default.yaml")
    camera = scenario.cameras["camera0"]
    # The camera looks at the far-left corner of the table; the cup stands at its centre.
    from pydrake.common.schema import Transform
    camera.X_PB = Transform(look_at([1.55, 0.6, 0.45], [1.0, 0.55, 0.0]))
    result = run_scenario(scenario, scenario_path="hidden target")
    check_result_keys(result)
    assert result["outcome"]["status"] == "failed"
    assert result["outcome"]["reason"] == "perception"


@pytest.mark.slow
def test_multi_object_scene_places_the_target_and_leaves_the_others():
    result = run("three_objects")
    check_result_keys(result)
    # Three objects and the shelf: perception segments every box on the table, fixtures too.
    assert result["perception"]["n_objects"] == 4
    assert result["outcome"]["status"] == "placed", result["outcome"]
    assert result["task_outcome"]["success"], result["task_outcome"]  # on the shelf


@pytest.mark.slow
@pytest.mark.xfail(reason="the full cup_03 upright is taken for a pot (kernel prior pot 0.86; "
                   "the logic pot 0.92, as at c0f6f9d), and with the kernel database rebuilt "
                   "(03fae7b) P(some part is grasped | pourOut) is 0.029, under "
                   "the supervisor's 0.03 gate: the run ends failed (logic) before any grasp",
                   strict=True)
def test_full_mug_for_pour_out_is_held_by_its_middle_and_stays_upright():
    result = run("tasks/mug_pour_out")
    check_result_keys(result)
    assert result["grasp"]["part"] == "middle"
    assert result["outcome"]["status"] == "placed", result["outcome"]
    # Placed in the pose it was picked in: never turned over (placed() checks the tilt).
    assert "tilted" in result["outcome"]["detail"]
    tilt_deg = float(result["outcome"]["detail"].split("tilted ")[1].rstrip("°"))
    assert tilt_deg < 20


def test_result_keys_check_rejects_a_malformed_result():
    bad = {"scenario": "x", "perception": {}, "timings": {},
           "outcome": {"status": "teleported", "reason": ""}}
    with pytest.raises(AssertionError):
        check_result_keys(bad)
    np.testing.assert_equal(set(OUTCOME_STATUSES), {"placed", "lifted", "grasped", "failed"})


def test_a_short_simulation_ends_as_timeout():
    """simulation_duration is honoured: 0.5 s is too short to pick and place."""
    result = run("default", simulation_duration=0.5)
    check_result_keys(result)
    assert (result["outcome"]["status"], result["outcome"]["reason"]) == ("failed", "timeout")
    assert result["timings"]["simulated_time"] == pytest.approx(0.5, abs=1e-9)
    assert result["config"]["simulation_duration"] == 0.5


def _plan_of(scenario):
    """The plan the planner makes for `scenario` (simulated just past the first attempt)."""
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder

    from tg_drake.diagram import add_pipeline

    builder = DiagramBuilder()
    pipeline = add_pipeline(builder, scenario=scenario)
    simulator = Simulator(builder.Build())
    context = simulator.get_mutable_context()
    simulator.AdvanceTo(scenario.pipeline.supervisor.planning_start + 0.05)
    status = pipeline.ports["plan_status"].Eval(pipeline.planner.GetMyContextFromRoot(context))
    assert status.plan is not None, status.reason
    return status.plan


def test_a_planner_field_set_in_yaml_is_recorded_and_changes_the_plan(tmp_path):
    from pydrake.common.yaml import yaml_dump_typed, yaml_load

    from tg_drake.planning.ik import make_arm_plant

    path = tmp_path / "lift.yaml"
    path.write_text((SCENARIOS / "default.yaml").read_text()
                    + "pipeline:\n  planner: {lift_height: 0.22}\n")
    high = load_scenario(path)
    assert yaml_load(data=yaml_dump_typed(high))["pipeline"]["planner"]["lift_height"] == 0.22
    plans = {h: _plan_of(s) for h, s in ((0.15, load_scenario(SCENARIOS / "default.yaml")),
                                          (0.22, high))}
    # The gripper's height at the end of the lift, from the planned joint positions.
    arm = make_arm_plant()
    rise = {}
    for h, plan in plans.items():
        z = []
        for t in (plan.t_grasp_closed, plan.t_lift_done):
            arm.plant.SetPositions(arm.plant_context, arm.iiwa, plan.q(t))
            z.append(arm.G.CalcPoseInWorld(arm.plant_context).translation()[2])
        rise[h] = z[1] - z[0]
    assert rise[0.15] == pytest.approx(0.15, abs=0.01)  # [m] IK position tolerance and the tilt
    assert rise[0.22] == pytest.approx(0.22, abs=0.01)
