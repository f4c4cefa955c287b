"""Every task scenario in scenarios/tasks/ runs through `run_scenario` and its task is judged by
physics: the task outcome in result.json says it succeeded, with its measure."""

from __future__ import annotations

from pathlib import Path

import pytest

from tg_drake.run import run_scenario
from tg_drake.scenario import load_scenario

TASKS = Path(__file__).resolve().parents[2] / "scenarios" / "tasks"


def test_every_task_scenario_is_a_case():
    cases = {"can_on_shelf", "can_sideways", "can_upsidedown", "glass_upright", "mug_pour_out",
             "glass_pour_in", "knife_pass", "mug_pass", "bottle_upright"}
    assert {p.stem for p in TASKS.glob("*.yaml")} >= cases


def task_outcome(cached_run, name: str) -> dict:
    result = cached_run(TASKS / f"{name}.yaml", None)
    assert result["outcome"]["task_outcome"] == result["task_outcome"]
    return result["task_outcome"]


def test_a_can_is_put_on_the_shelf(cached_run):
    task = task_outcome(cached_run, "can_on_shelf")
    assert task["task"] == "p&pOn"
    assert task["success"], task
    assert task["measure"] == {"surface": "shelf", "on_surface": True, "on_table": False}


@pytest.mark.slow
def test_an_upright_can_is_laid_on_its_side(cached_run):
    task = task_outcome(cached_run, "can_sideways")
    assert task["success"], task
    assert task["measure"]["rest_pose"] == "sideways" and task["measure"]["distance_m"] < 0.05


@pytest.mark.slow
def test_an_upright_can_is_turned_upside_down_in_the_hand(cached_run):
    task = task_outcome(cached_run, "can_upsidedown")
    assert task["success"], task
    assert task["measure"]["rest_pose"] == "upsidedown" and task["measure"]["distance_m"] < 0.05


@pytest.mark.slow
def test_a_glass_lying_down_is_stood_up_in_the_hand(cached_run):
    task = task_outcome(cached_run, "glass_upright")
    assert task["success"], task
    assert task["measure"]["rest_pose"] == "upright" and task["measure"]["distance_m"] < 0.05


@pytest.mark.slow
@pytest.mark.xfail(reason="the full cup_03 upright is taken for a pot (kernel prior pot 0.86; "
                   "the logic pot 0.92, as at c0f6f9d), and with the kernel database rebuilt "
                   "(03fae7b) P(some part is grasped | pourOut) is 0.029, under "
                   "the supervisor's 0.03 gate: the run ends failed (logic) before any grasp",
                   strict=True)
def test_a_full_mug_is_poured_into_the_bowl(cached_run):
    task = task_outcome(cached_run, "mug_pour_out")
    assert task["task"] == "pourOut" and task["measure"]["into"] == "bowl"
    counts = task["measure"]["counts"]
    assert sum(counts.values()) > 0  # every sphere accounted for, in one place each
    assert task["success"], task


@pytest.mark.slow
def test_an_empty_glass_is_filled_under_the_dispenser(cached_run):
    task = task_outcome(cached_run, "glass_pour_in")
    assert task["task"] == "pourIn"
    assert task["success"], task


@pytest.mark.slow
def test_where_the_reach_forbids_turning_it_in_the_hand_a_place_and_regrasp_stands_it_up(
        cached_run):
    """A lying bottle to stand up: the first leg puts it down in an intermediate resting pose,
    perception looks again, the final leg stands it up (two legs: 40 s simulation_duration)."""
    result = cached_run(TASKS / "bottle_upright.yaml", None)
    outcome, task = result["outcome"], result["task_outcome"]
    assert outcome["status"] == "placed", outcome
    assert len(outcome["legs"]) == 1 and outcome["legs"][0]["placed_pose"] in ("sideways",
                                                                               "upsidedown")
    assert task["success"], task
    assert task["measure"]["rest_pose"] == "upright" and task["measure"]["distance_m"] < 0.05


def passed_over(result: dict) -> dict:
    """The pass's task outcome, checked for the receiver's hold: both its pads on the object, the
    robot's and the table's off it, its height steady, for the receiver's hold duration."""
    task = result["task_outcome"]
    assert task["task"] == "pass"
    assert task["success"], (task, result["outcome"])
    m = task["measure"]
    assert m["receiver_held"] and m["receiver_pads"] == [True, True]
    assert not m["robot_touches"] and not m["on_table"]
    assert m["height_change_m"] <= 0.01 and m["held_for_s"] >= 1.0
    # The robot's own part of a pass: grasped, lifted and let go in the air, not placed.
    assert (result["outcome"]["status"], result["outcome"]["reason"]) == ("lifted", "")
    assert result["outcome"]["detail"].startswith("handed over")
    return task


@pytest.mark.slow
def test_a_mug_is_handed_over_to_the_receiver(cached_run):
    passed_over(cached_run(TASKS / "mug_pass.yaml", None))


@pytest.mark.slow
def test_a_knife_is_handed_over_to_the_receiver(cached_run):
    task = passed_over(cached_run(TASKS / "knife_pass.yaml", None))
    # The paper's pass: the robot holds the blade, the receiver gets the handle (measured on the
    # knife's labelled mesh at the receiver's pads).
    assert task["measure"]["received_part"] == "handle", task


def test_a_receiver_that_cannot_reach_fails_the_pass_saying_so():
    # The default cup, its receiver's mount reaching only 0.1 m from where it waits: no plan is
    # made (the receiver's grasp is checked once the robot's waypoints are solved), nothing is
    # simulated past planning.
    scenario = load_scenario(TASKS.parent / "default.yaml")
    scenario.receiver = load_scenario(TASKS / "mug_pass.yaml").receiver
    scenario.receiver.reach = 0.1
    result = run_scenario(scenario, scenario_path="receiver out of reach")
    assert (result["outcome"]["status"], result["outcome"]["reason"]) == ("failed", "unreachable")
    task = result["task_outcome"]
    assert task["task"] == "pass" and not task["success"]
    assert "hand-over: the receiver cannot reach" in task["detail"], task
    assert "(reach 0.1 m)" in task["detail"]
    # In a pass the hand-over depends on the robot's grasp alone: a part none of whose
    # candidates can be handed over is told to the logic as unreachable, and the next one tried.
    assert "middle" in result["outcome"]["unreachable_parts"]
    assert result["outcome"]["requeries"] >= 1
    assert "can be picked and handed over" in result["outcome"]["detail"]
