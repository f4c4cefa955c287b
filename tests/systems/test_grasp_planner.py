"""GraspPlanner alone (fixed inputs): it plans the attempt it is asked for and reports which part
failed and why (what to do about it is the Supervisor's: tests/systems/test_supervisor.py)."""

from __future__ import annotations

import numpy as np
import pytest
from grasp_helpers import grasp_pose, ranked, scene_with_box
from pydrake.systems.analysis import Simulator

from tg_drake.planning.planner import PlannerConfig
from tg_drake.systems.grasp_planner import GraspPlanner
from tg_drake.systems.plan_messages import PlanRequest, PlanStatus

START = 0.5  # [s] the planner's first event
Q_MEASURED = np.array([0.1, -0.5, 0.05, -1.8, 0.0, 1.1, 0.2])  # a posture near IIWA_HOME


SCENE = scene_with_box([0.75, 0.1, 0.10])
TOP = grasp_pose([0.75, 0.1, 0.17], [0, 0, -1], [0, 1, 0])
SIDE = grasp_pose([0.75, 0.1, 0.15], [1, 0, 0], [0, 1, 0])
# Grasps of the bottom from under the table: never reachable.
FROM_BELOW = [grasp_pose([0.75, 0.1, 0.03], [0, 0, 1], [0, 1, 0]),
              grasp_pose([0.75, 0.1, 0.03], [0, 0, 1], [1, 0, 0])]


def fixed_inputs(planner, scene, grasps):
    context = planner.CreateDefaultContext()
    planner.get_scene_description_input_port().FixValue(context, scene)
    planner.get_ranked_grasps_input_port().FixValue(context, grasps)
    planner.get_iiwa_state_input_port().FixValue(context, np.concatenate([Q_MEASURED,
                                                                          np.zeros(7)]))
    return context


def desired(planner, context):
    return planner.get_iiwa_desired_state_output_port().Eval(context)


def status(planner, context) -> PlanStatus:
    return planner.get_plan_status_output_port().Eval(context)


@pytest.fixture(scope="module")
def reachable_run():
    """The planner with a reachable top grasp, run to just after its first event."""
    planner = GraspPlanner(place_xy=(0.75, -0.25), start_time=START)
    context = fixed_inputs(planner, SCENE, ranked([(TOP, "top"), (SIDE, "middle")]))
    simulator = Simulator(planner, context)
    simulator.Initialize()
    before = {"t": 0.3}
    simulator.AdvanceTo(before["t"])
    before.update(q=desired(planner, context).copy(),
                  wsg=planner.get_wsg_position_output_port().Eval(context)[0],
                  status=status(planner, context))
    simulator.AdvanceTo(START + 0.01)
    return planner, simulator, context, before


def test_holds_the_measured_posture_before_planning(reachable_run):
    _, _, _, before = reachable_run
    np.testing.assert_array_equal(before["q"], np.concatenate([Q_MEASURED, np.zeros(7)]))
    assert before["wsg"] == 0.11  # open
    assert before["status"].status == "planning"
    assert before["status"].plan is None


def test_follows_the_plan_after_the_planning_event(reachable_run):
    planner, simulator, context, _ = reachable_run
    s = status(planner, context)
    assert s.status == "executing"
    assert (s.part, s.candidate) == ("top", 0)
    assert s.t_plan == pytest.approx(START, abs=1e-12)
    np.testing.assert_array_equal(s.X_WG, TOP)
    plan = s.plan
    # The plan starts at the held posture, so the command is continuous at the event.
    np.testing.assert_allclose(plan.q(0.0), Q_MEASURED, atol=1e-9)
    for t in (START + 0.01, START + plan.t_grasp_closed, START + plan.t_lift_done):
        simulator.AdvanceTo(t)
        x = desired(planner, context)
        np.testing.assert_allclose(x[:7], plan.q(t - START), atol=1e-12)
        np.testing.assert_allclose(x[7:], plan.v(t - START), atol=1e-12)
        assert planner.get_wsg_position_output_port().Eval(context)[0] == pytest.approx(
            plan.width(t - START), abs=1e-12)
    # Closed and squeezing (commanded past closed, so the grip is the force limit), lifting.
    assert planner.get_wsg_position_output_port().Eval(context)[0] == PlannerConfig().closed_width
    assert PlannerConfig().closed_width < 0.0
    simulator.AdvanceTo(START + plan.duration + 0.1)
    assert status(planner, context).status == "done"
    np.testing.assert_allclose(desired(planner, context)[7:], 0.0, atol=1e-12)
    assert status(planner, context).unreachable_parts == ()


def test_unreachable_leading_part_is_reported_and_the_next_attempt_leaves_it_out():
    """The bottom leads the ranking but can only be grasped from under the table: the first
    attempt fails and names it (the arm holds on); asked again without it, the next event plans
    the top."""
    planner = GraspPlanner(place_xy=(0.75, -0.25), start_time=START)
    grasps = ranked([(FROM_BELOW[0], "bottom"), (FROM_BELOW[1], "bottom"), (TOP, "top")])
    context = fixed_inputs(planner, SCENE, grasps)
    planner.get_plan_request_input_port().FixValue(context, PlanRequest(attempt=1))
    simulator = Simulator(planner, context)
    simulator.Initialize()
    simulator.AdvanceTo(START + 0.01)
    s = status(planner, context)
    assert (s.status, s.attempt, s.unreachable_parts, s.failed_part) == (
        "failed", 1, ("bottom",), "bottom")
    assert s.reason
    np.testing.assert_array_equal(desired(planner, context)[:7], Q_MEASURED)  # still holding
    simulator.AdvanceTo(START + 0.06)  # the same request is answered once only
    assert (status(planner, context).status, status(planner, context).attempt) == ("failed", 1)
    planner.get_plan_request_input_port().FixValue(
        context, PlanRequest(attempt=2, exclude_parts=("bottom",)))
    n1 = s.ik_solves
    simulator.AdvanceTo(START + 0.11)  # the next event, 0.05 s later
    s = status(planner, context)
    assert (s.status, s.attempt, s.part, s.candidate) == ("executing", 2, "top", 2)
    assert s.t_plan == pytest.approx(START + 0.10, abs=1e-9)
    assert s.ik_solves > n1  # summed over the requests answered


def test_a_request_that_runs_out_of_its_ik_budget_fails_and_says_so():
    """Placed out of reach, with a budget of one solver call: the request ends after the first
    candidate's pick, failed, its reason naming the setting."""
    planner = GraspPlanner(place_xy=(0.0, -1.2), start_time=START,
                           config=PlannerConfig(max_ik_solves=1))
    context = fixed_inputs(planner, SCENE, ranked([(TOP, "top"), (SIDE, "top")]))
    planner.get_plan_request_input_port().FixValue(context, PlanRequest(attempt=1))
    simulator = Simulator(planner, context)
    simulator.Initialize()
    simulator.AdvanceTo(START + 0.01)
    s = status(planner, context)
    assert (s.status, s.attempt) == ("failed", 1)
    assert "(pipeline.planner.max_ik_solves)" in s.reason
    assert s.ik_solves >= 1


def test_without_a_request_nothing_is_planned():
    planner = GraspPlanner(place_xy=(0.75, -0.25), start_time=0.0)
    context = fixed_inputs(planner, SCENE, ranked([(TOP, "top")]))
    planner.get_plan_request_input_port().FixValue(context, PlanRequest(attempt=0))
    simulator = Simulator(planner, context)
    simulator.Initialize()
    simulator.AdvanceTo(0.11)
    s = status(planner, context)
    assert (s.status, s.attempt, s.plan) == ("planning", 0, None)


def test_nothing_left_to_try_blames_no_part():
    """Every part excluded: the attempt fails without naming a part."""
    planner = GraspPlanner(place_xy=(0.75, -0.25), start_time=0.0)
    far = scene_with_box([1.6, 0.0, 0.10])
    grasps = ranked([(grasp_pose([1.6, 0.0, 0.15], [1, 0, 0], [0, 1, 0]), "middle"),
                     (grasp_pose([1.6, 0.0, 0.17], [0, 0, -1], [0, 1, 0]), "top")])
    context = fixed_inputs(planner, far, grasps)
    planner.get_plan_request_input_port().FixValue(context, PlanRequest(attempt=1))
    simulator = Simulator(planner, context)
    simulator.Initialize()
    simulator.AdvanceTo(0.01)
    assert status(planner, context).failed_part == "middle"  # out of reach
    planner.get_plan_request_input_port().FixValue(
        context, PlanRequest(attempt=2, exclude_parts=("middle", "top")))
    simulator.AdvanceTo(0.06)
    s = status(planner, context)
    assert (s.status, s.attempt, s.failed_part) == ("failed", 2, None)
    assert "no candidate grasps left" in s.reason
    np.testing.assert_array_equal(desired(planner, context)[:7], Q_MEASURED)  # holds on


def test_unreachable_place_gives_up_without_blaming_the_part():
    planner = GraspPlanner(place_xy=(1.6, 0.0), start_time=0.0)
    context = fixed_inputs(planner, SCENE, ranked([(TOP, "top")]))
    simulator = Simulator(planner, context)
    simulator.Initialize()
    simulator.AdvanceTo(0.01)
    s = status(planner, context)
    assert (s.status, s.unreachable_parts, s.failed_part) == ("failed", (), None)
    assert s.picked_parts == ("top",)  # the supervisor's reason: unreachable, not would_not_hold
    assert "picked but not placed" in s.reason


@pytest.mark.parametrize("late", [False, True])
def test_a_reseat_request_while_the_pads_stand_open_delays_the_retreat(late):
    """``plan_request.reseats`` one more than answered: at its next event, while the plan's pads
    stand open at the place, the planner inserts a re-seat (the pads close and open again) and
    follows the new plan; asked after that pause, it answers with the plan unchanged."""
    planner = GraspPlanner(place_xy=(0.75, -0.25), start_time=START)
    context = fixed_inputs(planner, SCENE, ranked([(TOP, "top")]))
    planner.get_plan_request_input_port().FixValue(context, PlanRequest(attempt=1))
    simulator = Simulator(planner, context)
    simulator.Initialize()
    simulator.AdvanceTo(START + 0.01)
    plan = status(planner, context).plan
    t_ask = START + (plan.t_place_done + 0.01 if late else plan.t_opened)
    simulator.AdvanceTo(t_ask)
    planner.get_plan_request_input_port().FixValue(context, PlanRequest(attempt=1, reseats=1))
    simulator.AdvanceTo(t_ask + 0.06)  # one planning period
    s = status(planner, context)
    assert (s.status, s.attempt, s.reseats) == ("executing", 1, 1)
    if late:
        assert s.plan is plan
        return
    assert s.plan.duration > plan.duration and s.plan.t_opened > plan.t_place_done
    c = PlannerConfig()
    simulator.AdvanceTo(START + s.plan.t_opened - c.open_duration - c.squeeze_duration - 0.05)
    assert planner.get_wsg_position_output_port().Eval(context)[0] == c.closed_width
    np.testing.assert_allclose(desired(planner, context)[:7], plan.q(plan.t_place_done),
                               atol=1e-12)
