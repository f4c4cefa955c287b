"""Supervisor alone (fixed inputs) and in a small loop with the real planner and a stand-in for
the logic and the scorer: the gate, re-checked after every re-query; the re-query policy; waiting
for plans. (The execution monitor runs on a plant: tests/integration/test_grasp_planner_station.py
and the scenario tests.)"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from grasp_helpers import grasp_pose, ranked, scene_with_box
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.plant import ContactResults
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.primitives import ConstantValueSource, ConstantVectorSource

import tg_drake.systems.supervisor as supervisor_module
from tg_drake.outcome import HandContact, HandGeometries
from tg_drake.systems.grasp_planner import GraspPlanner
from tg_drake.systems.plan_messages import PlanRequest, PlanState, PlanStatus
from tg_drake.systems.supervisor import (
    MonitorModel,
    Outcome,
    Phase,
    Reason,
    Status,
    Supervisor,
    SupervisorConfig,
    _Memory,
)
from tg_drake.types import (
    PART_LABELS,
    GraspCandidates,
    GraspSemantics,
    PerceptionStatus,
    SceneDescription,
)

# No plant: the gate and the re-query policy never read the monitor's geometry.
NO_MODEL = MonitorModel(HandGeometries(frozenset(), frozenset(), frozenset(), frozenset(),
                                       gripper=0), object_body=0)
CONFIG = SupervisorConfig(planning_start=0.0, period=0.01, planning_timeout=0.5)
Q_MEASURED = np.array([0.1, -0.5, 0.05, -1.8, 0.0, 1.1, 0.2])  # a posture near IIWA_HOME


def semantics(grasp_probability=0.5, part=None, collisions=()) -> GraspSemantics:
    return GraspSemantics(category={"cup": 1.0}, task={"pass": 1.0},
                          part=part or {"bottom": 0.6, "top": 0.4}, given_task="pass",
                          collisions=tuple(collisions), grasp_probability=grasp_probability)


SCENE = scene_with_box([0.75, 0.1, 0.10])
TOP = grasp_pose([0.75, 0.1, 0.17], [0, 0, -1], [0, 1, 0])
FROM_BELOW = grasp_pose([0.75, 0.1, 0.03], [0, 0, 1], [0, 1, 0])  # never reachable
GRASPS = ranked([(FROM_BELOW, "bottom"), (TOP, "top")])


class Fixed:
    """The supervisor alone, its inputs fixed; `advance` moves simulated time."""

    def __init__(self, *, config=CONFIG, scene=SCENE, meaning=None, grasps=GRASPS, **task):
        self.supervisor = Supervisor(config=config, model=NO_MODEL, **task)
        self.context = self.supervisor.CreateDefaultContext()
        s = self.supervisor
        s.get_scene_description_input_port().FixValue(self.context, scene)
        s.get_grasp_semantics_input_port().FixValue(self.context, meaning or semantics())
        s.get_ranked_grasps_input_port().FixValue(self.context, grasps)
        self.plan(PlanStatus(PlanState.planning))
        s.get_wsg_state_input_port().FixValue(self.context, np.zeros(4))
        s.get_body_poses_input_port().FixValue(self.context, [RigidTransform()])
        s.get_contact_results_input_port().FixValue(self.context, ContactResults())
        self.simulator = Simulator(s, self.context)
        self.simulator.Initialize()

    def plan(self, status: PlanStatus):
        self.supervisor.get_plan_status_input_port().FixValue(self.context, status)

    def meaning(self, value: GraspSemantics):
        self.supervisor.get_grasp_semantics_input_port().FixValue(self.context, value)

    def advance(self, t: float):
        self.simulator.AdvanceTo(t)

    @property
    def outcome(self) -> Outcome:
        return self.supervisor.get_outcome_output_port().Eval(self.context)

    @property
    def request(self) -> PlanRequest:
        return self.supervisor.get_plan_request_output_port().Eval(self.context)

    @property
    def collisions(self) -> tuple:
        return self.supervisor.get_collisions_output_port().Eval(self.context)


def failed(attempt, part=None, reason="pre-grasp pose unreachable (test)") -> PlanStatus:
    return PlanStatus(PlanState.failed, attempt=attempt,
                      unreachable_parts=(part,) if part else (), reason=reason)


def test_gate_passes_and_asks_for_the_first_plan():
    f = Fixed()
    assert f.request == PlanRequest(attempt=0) and not f.outcome.final  # before the first check
    f.advance(0.001)
    assert f.request == PlanRequest(attempt=1, exclude_parts=())
    assert (f.outcome.status, f.outcome.final) == (Status.pending, False)
    assert "attempt 1" in f.outcome.detail


def test_a_given_task_gets_a_failed_task_outcome_when_the_run_ends_early():
    f = Fixed(meaning=semantics(grasp_probability=0.01), task="p&pInUpsidedown")
    f.advance(0.001)
    task = f.outcome.task_outcome
    assert f.outcome.final and task is not None
    assert (task.task, task.success) == ("p&pInUpsidedown", False)
    assert "not done" in task.detail and "logic" in task.detail
    assert f.outcome.as_dict()["task_outcome"]["success"] is False


def test_the_dispenser_opens_while_a_pour_in_plan_holds_the_container_under_it():
    f = Fixed(task="pourIn", dispense_duration=1.5)
    port = f.supervisor.get_dispenser_command_output_port()
    f.advance(0.001)
    # The monitor's first check (the grasp) lies after this test's times: only the hold matters.
    plan = SimpleNamespace(t_grasp_closed=100.0, t_lift_done=101.0, duration=102.0,
                           t_pour=(2.0, 4.5))
    f.plan(PlanStatus(PlanState.executing, attempt=1, t_plan=0.5, plan=plan))
    command = []
    for t in (0.5, 2.4, 2.6, 3.9, 4.1, 6.0):
        f.advance(t)
        command.append(port.Eval(f.context)[0])
    assert command == [0.0, 0.0, 1.0, 1.0, 0.0, 0.0]  # open over [2.5, 4.0) s


def test_no_task_given_no_task_outcome():
    f = Fixed(meaning=semantics(grasp_probability=0.01))
    f.advance(0.001)
    assert f.outcome.final and f.outcome.task_outcome is None
    assert f.outcome.as_dict()["task_outcome"] is None


@pytest.mark.parametrize("kwargs, detail", [
    (dict(meaning=semantics(grasp_probability=0.01)), "P(some part is grasped) = 0.010 < 0.03"),
    (dict(meaning=semantics(part={"bottom": 0.0, "top": 0.0})), "ruled every grasp out"),
    (dict(grasps=GraspCandidates(GRASPS.X_WG, GRASPS.parts, GRASPS.p_part, GRASPS.p_local,
                                 np.zeros(2))), "no pre-grasp hypothesis with a non-zero score"),
])
def test_the_logic_veto_fails_the_run_before_any_plan(kwargs, detail):
    f = Fixed(**kwargs)
    f.advance(0.001)
    o = f.outcome
    assert (o.status, o.reason, o.final) == (Status.failed, Reason.logic, True)
    assert detail in o.detail
    assert f.request.attempt == 0  # the planner was never asked


@pytest.mark.parametrize("scene, detail", [
    (SceneDescription(objects=[], X_WT=np.eye(4)), "no object on the table"),
    (SceneDescription(objects=SCENE.objects, X_WT=np.eye(4), target=None), "target's position"),
])
def test_nothing_perceived_at_the_target_fails_as_perception(scene, detail):
    f = Fixed(scene=scene)
    f.advance(0.001)
    assert (f.outcome.status, f.outcome.reason) == ("failed", "perception")
    assert detail in f.outcome.detail


def test_an_unreachable_part_becomes_collision_evidence_and_the_planner_is_asked_again():
    f = Fixed()
    f.advance(0.001)
    f.plan(failed(1, "bottom"))
    f.advance(0.011)  # the check that reads the failure
    assert f.collisions == ("bottom",)
    assert f.request.attempt == 1  # not yet: the gate is checked first, with the new evidence
    assert (f.outcome.final, f.outcome.requeries, f.outcome.unreachable_parts) == (
        False, 1, ("bottom",))
    f.meaning(semantics(collisions=("bottom",), part={"bottom": 0.0, "top": 1.0}))
    f.advance(0.021)
    assert f.request == PlanRequest(attempt=2, exclude_parts=("bottom",))


def test_the_gate_is_checked_again_after_a_requery():
    """Told the bottom cannot be reached, the logic rules grasping out: the run ends there, as
    unreachable (the evidence came from the planner), and the planner is not asked again."""
    f = Fixed()
    f.advance(0.001)
    f.plan(failed(1, "bottom"))
    f.advance(0.011)
    f.meaning(semantics(grasp_probability=0.01, collisions=("bottom",)))
    f.advance(0.021)
    o = f.outcome
    assert (o.status, o.reason, o.requeries, o.unreachable_parts) == (
        "failed", "unreachable", 1, ("bottom",))
    assert "P(some part is grasped) = 0.010" in o.detail and "bottom" in o.detail
    # Why the bottom cannot be reached: the planner's reason, which the logic never hears.
    assert "told bottom cannot be reached: pre-grasp pose unreachable (test)" in o.detail
    assert f.request.attempt == 1


def test_gives_up_after_max_requeries():
    f = Fixed(config=SupervisorConfig(planning_start=0.0, period=0.01, max_requeries=0))
    f.advance(0.001)
    f.plan(failed(1, "bottom"))
    f.advance(0.011)
    o = f.outcome
    assert (o.status, o.reason, o.requeries, o.unreachable_parts) == (
        "failed", "unreachable", 0, ("bottom",))
    assert o.detail.startswith("gave up after 0 re-queries; pre-grasp pose unreachable")


def test_the_first_informative_failure_stays_in_the_detail():
    f = Fixed()
    f.advance(0.001)
    f.plan(failed(1, "bottom", reason="pre-grasp pose unreachable (bottom)"))
    f.advance(0.011)
    f.advance(0.021)  # the gate again (unchanged semantics pass): attempt 2
    assert f.request.attempt == 2
    f.plan(failed(2, None, reason="no candidate grasps left to try"))
    f.advance(0.031)
    o = f.outcome
    assert (o.status, o.reason) == ("failed", "unreachable")
    assert "no candidate grasps left to try" in o.detail
    assert "pre-grasp pose unreachable (bottom)" in o.detail


def test_a_part_that_would_not_hold_is_told_apart_from_an_unreachable_one():
    """The feasibility stage found no holding grasp on the bottom: when the plan fails with no
    part blamed for reach, the bottom is no_hold evidence (not collision), the planner leaves it
    out, and a run that ends there fails as would_not_hold."""
    import dataclasses

    unholdable = dataclasses.replace(GRASPS, unholdable_parts=("bottom",))
    f = Fixed(grasps=unholdable)
    f.advance(0.001)
    f.plan(failed(1, None, reason="no candidate grasps left to try"))
    f.advance(0.011)
    no_hold = f.supervisor.get_no_hold_output_port().Eval(f.context)
    assert (no_hold, f.collisions) == (("bottom",), ())
    f.meaning(semantics(part={"bottom": 0.0, "top": 1.0}))
    f.advance(0.021)
    assert f.request == PlanRequest(attempt=2, exclude_parts=("bottom",))
    f.plan(failed(2, None, reason="no candidate grasps left to try"))
    f.advance(0.031)
    o = f.outcome
    assert (o.status, o.reason, o.unreachable_parts) == ("failed", "would_not_hold", ())
    assert "no grasp on bottom would hold" in o.detail


def test_a_part_picked_but_not_placed_fails_as_unreachable_though_another_would_not_hold():
    """The bottom would not hold; the top can be picked but the place (or pour) pose is out of
    reach: the run ends unreachable, not would_not_hold."""
    import dataclasses

    unholdable = dataclasses.replace(GRASPS, unholdable_parts=("bottom",))
    f = Fixed(grasps=unholdable)
    f.advance(0.001)
    picked_not_placed = dataclasses.replace(
        failed(1, None, reason="the object can be picked but not placed at (0.850, -0.300) m: "
               "pour pose unreachable"), picked_parts=("top",))
    f.plan(picked_not_placed)
    f.advance(0.011)
    f.meaning(semantics(part={"bottom": 0.0, "top": 1.0}))
    f.advance(0.021)
    f.plan(dataclasses.replace(picked_not_placed, attempt=2))
    f.advance(0.031)
    o = f.outcome
    assert (o.status, o.reason) == ("failed", "unreachable")
    assert "pour pose unreachable" in o.detail


def test_no_plan_within_the_planning_timeout_fails_as_timeout():
    f = Fixed()
    f.advance(0.49)
    assert not f.outcome.final
    f.advance(0.52)
    assert (f.outcome.status, f.outcome.reason) == ("failed", "timeout")
    assert "planning_timeout = 0.5 s" in f.outcome.detail


def test_a_bad_config_names_its_field():
    from tg_drake.errors import ScenarioError
    with pytest.raises(ScenarioError, match="max_requeries"):
        SupervisorConfig(max_requeries=-1).validate()


class _LogicAndScorer(LeafSystem):
    """A stand-in for the logic + DGI: given collisions, P(some part is grasped) drops to
    `p_after` and the parts in collision lose their candidates; counts its calls."""

    def __init__(self, grasps: GraspCandidates, *, p_after: float):
        super().__init__()
        self.grasps, self.p_after, self.seen = grasps, p_after, []
        self._collisions = self.DeclareAbstractInputPort("collisions", AbstractValue.Make(()))
        self.DeclareAbstractOutputPort("grasp_semantics",
                                       lambda: AbstractValue.Make(semantics()), self._semantics)
        self.DeclareAbstractOutputPort("ranked_grasps", lambda: AbstractValue.Make(grasps),
                                       self._ranked)

    def _semantics(self, context, output):
        collisions = self._collisions.Eval(context)
        output.set_value(semantics(self.p_after if collisions else 0.5, collisions=collisions))

    def _ranked(self, context, output):
        collisions = self._collisions.Eval(context)
        self.seen.append(collisions)
        keep = np.array([PART_LABELS[p] not in collisions for p in self.grasps.parts], bool)
        g = self.grasps
        output.set_value(GraspCandidates(g.X_WG[keep], g.parts[keep], g.p_part[keep],
                                         g.p_local[keep], g.score[keep]))


def closed_loop(p_after: float):
    """Planner + supervisor + stand-in, the arm's state fixed; simulated to 0.3 s."""
    builder = DiagramBuilder()
    config = SupervisorConfig(planning_start=0.0, period=0.01)
    planner = builder.AddSystem(GraspPlanner(place_xy=(0.75, -0.25), start_time=config.period))
    supervisor = builder.AddSystem(Supervisor(config=config, model=NO_MODEL))
    stages = builder.AddSystem(_LogicAndScorer(GRASPS, p_after=p_after))
    scene = builder.AddSystem(ConstantValueSource(AbstractValue.Make(SCENE)))
    arm = builder.AddSystem(ConstantVectorSource(np.concatenate([Q_MEASURED, np.zeros(7)])))
    for port, source in ((planner.get_scene_description_input_port(), scene.get_output_port()),
                         (supervisor.get_scene_description_input_port(), scene.get_output_port()),
                         (planner.get_ranked_grasps_input_port(),
                          stages.GetOutputPort("ranked_grasps")),
                         (supervisor.get_ranked_grasps_input_port(),
                          stages.GetOutputPort("ranked_grasps")),
                         (supervisor.get_grasp_semantics_input_port(),
                          stages.GetOutputPort("grasp_semantics")),
                         (planner.get_iiwa_state_input_port(), arm.get_output_port()),
                         (supervisor.get_plan_status_input_port(),
                          planner.get_plan_status_output_port()),
                         (planner.get_plan_request_input_port(),
                          supervisor.get_plan_request_output_port()),
                         (stages.get_input_port(), supervisor.get_collisions_output_port())):
        builder.Connect(source, port)
    fixed = builder.AddSystem(ConstantVectorSource(np.zeros(4)))
    builder.Connect(fixed.get_output_port(), supervisor.get_wsg_state_input_port())
    poses = builder.AddSystem(ConstantValueSource(AbstractValue.Make([RigidTransform()])))
    builder.Connect(poses.get_output_port(), supervisor.get_body_poses_input_port())
    contacts = builder.AddSystem(ConstantValueSource(AbstractValue.Make(ContactResults())))
    builder.Connect(contacts.get_output_port(), supervisor.get_contact_results_input_port())
    diagram = builder.Build()  # raises on an algebraic loop
    simulator = Simulator(diagram)
    simulator.Initialize()
    simulator.AdvanceTo(0.3)
    root = simulator.get_context()
    return (supervisor.get_outcome_output_port().Eval(supervisor.GetMyContextFromRoot(root)),
            planner.get_plan_status_output_port().Eval(planner.GetMyContextFromRoot(root)),
            stages)


def test_closed_loop_replans_without_the_unreachable_part():
    outcome, status, stages = closed_loop(p_after=0.5)
    assert (status.status, status.attempt, status.part) == ("executing", 2, "top")
    assert status.candidate == 0  # index in the re-ranked grasps, which lack the bottom
    assert ("bottom",) in stages.seen
    assert (outcome.final, outcome.unreachable_parts, outcome.requeries) == (
        False, ("bottom",), 1)


def test_closed_loop_stops_when_the_logic_vetoes_after_the_requery():
    outcome, status, _ = closed_loop(p_after=0.01)
    assert (outcome.status, outcome.reason) == ("failed", "unreachable")
    assert "P(some part is grasped) = 0.010" in outcome.detail
    assert (status.status, status.attempt) == ("failed", 1)  # the top was never planned


def test_a_regrasp_leg_then_perception_looks_again_and_the_final_leg_is_the_runs(monkeypatch):
    """The legs (place-and-regrasp) with a stub plan and a stub perception status: the first
    leg's plan ends placed, the supervisor asks perception to look again (perception_request 1),
    waits for the new latch, runs the gate, asks for the next leg (no regrasp allowed any more:
    max_regrasps 1) and judges the final leg's task; the outcome records the leg."""
    held = iter([True, True, False] * 2)  # closed, lifted, let go: leg 1, then the final leg
    monkeypatch.setattr(supervisor_module, "hand_contact", lambda contacts, **k: HandContact(
        0.05, True, True, 2, *((40.0, 40.0) if next(held) else (0.0, 0.0))))
    monkeypatch.setattr(supervisor_module, "touches_table", lambda *a, **k: True)
    monkeypatch.setattr(supervisor_module, "placed", lambda *a, **k: (True, "placed 0.3 cm"))
    f = Fixed(task="p&pInUpright",
              config=SupervisorConfig(planning_start=0.0, period=0.01, planning_timeout=0.5))
    look = f.supervisor.get_perception_status_input_port()
    look.FixValue(f.context, PerceptionStatus(ok=True, request=0))
    looks = f.supervisor.get_perception_request_output_port()
    f.advance(0.001)
    assert f.request == PlanRequest(attempt=1, regrasp=True) and looks.Eval(f.context) == 0

    X_intermediate = np.eye(4)
    X_intermediate[:2, 3] = [0.8, -0.1]
    leg = SimpleNamespace(regrasp=True, t_grasp_closed=0.1, t_lift_done=0.2, duration=0.3,
                          t_pour=None, R_turn=None, X_WO_place=X_intermediate)
    f.plan(PlanStatus(PlanState.executing, attempt=1, part="middle", t_plan=0.01, plan=leg))
    f.advance(0.35)
    o = f.outcome
    assert not o.final and "waiting for perception to look again" in o.detail
    assert looks.Eval(f.context) == 1
    assert f.supervisor.get_target_xy_output_port().Eval(f.context) == (0.8, -0.1)
    assert [dict(x)["part"] for x in o.legs] == ["middle"]
    assert dict(o.legs[0])["placed_pose"] == "upright"  # body pose identity: upright
    f.advance(0.45)
    assert f.request.attempt == 1  # still looking: the latch serves request 0

    look.FixValue(f.context, PerceptionStatus(ok=True, request=1))
    f.advance(0.48)
    assert f.request == PlanRequest(attempt=2, regrasp=False)  # the bound: one regrasp leg
    final = SimpleNamespace(regrasp=False, t_grasp_closed=0.1, t_lift_done=0.2, duration=0.3,
                            t_pour=None, R_turn=None, X_WO_place=np.eye(4))
    f.plan(PlanStatus(PlanState.executing, attempt=2, part="middle", t_plan=0.48, plan=final))
    f.advance(0.9)
    o = f.outcome
    assert (o.status, o.final) == ("placed", True)
    assert o.task_outcome.success and o.task_outcome.measure["rest_pose"] == "upright"
    assert o.as_dict()["legs"] == [{"part": "middle", "ended": "placed",
                                    "placed_pose": "upright", "xy": [0.8, -0.1], "t_end": 0.31}]


def test_when_the_regrasp_bound_is_reached_the_failure_says_so():
    f = Fixed(task="p&pInUpright")
    leg = (("part", "middle"), ("ended", "placed"), ("placed_pose", "sideways"),
           ("xy", [0.8, 0.0]), ("t_end", 1.0))
    f.context.get_mutable_abstract_state(0).set_value(
        _Memory(phase=Phase.planning, attempt=2, legs=(leg,), t_leg=0.0))
    f.plan(failed(2, None, reason="the object can be picked but not placed: ..., the object "
                  "turned to rest upright in the hand (no place-and-regrasp leg allowed: "
                  "pipeline.supervisor.max_regrasps)"))
    f.advance(0.011)
    o = f.outcome
    assert (o.status, o.reason, len(o.legs)) == ("failed", "unreachable", 1)
    assert o.detail.startswith("after 1 place-and-regrasp leg(s) (max_regrasps = 1)")
    assert "no place-and-regrasp leg allowed" in o.detail and not o.task_outcome.success


def test_with_retries_a_missed_grasp_is_looked_at_again_once_its_plan_is_over(monkeypatch):
    """max_retries 1: plans end with the arm home (return_home); the missed grasp is recorded,
    perception asked to look only once the plan is over, then the next attempt is requested
    (return_home off: no retry left); a second miss ends the run, saying so."""
    monkeypatch.setattr(supervisor_module, "hand_contact",
                        lambda contacts, **k: HandContact(0.0, False, False, 0))
    f = Fixed(config=SupervisorConfig(planning_start=0.0, period=0.01, planning_timeout=0.5,
                                      max_retries=1))
    look = f.supervisor.get_perception_status_input_port()
    look.FixValue(f.context, PerceptionStatus(ok=True, request=0))
    looks = f.supervisor.get_perception_request_output_port()
    f.advance(0.001)
    assert f.request == PlanRequest(attempt=1, return_home=True)
    plan = SimpleNamespace(regrasp=False, t_grasp_closed=0.1, t_lift_done=0.2, duration=0.6,
                           t_pour=None, R_turn=None, X_WO_place=np.eye(4))
    f.plan(PlanStatus(PlanState.executing, attempt=1, part="top", t_plan=0.01, plan=plan))
    f.advance(0.15)  # the miss
    o = f.outcome
    assert not o.final and [dict(x)["ended"] for x in o.legs] == ["missed"]
    assert looks.Eval(f.context) == 0  # the arm is still on its way home
    f.advance(0.62)
    assert looks.Eval(f.context) == 1 and f.request.attempt == 1
    look.FixValue(f.context, PerceptionStatus(ok=True, request=1))
    f.advance(0.65)
    assert f.request == PlanRequest(attempt=2, return_home=False)
    f.plan(PlanStatus(PlanState.executing, attempt=2, part="top", t_plan=0.65, plan=plan))
    f.advance(0.8)
    o = f.outcome
    assert (o.status, o.reason, len(o.legs)) == ("failed", "missed", 1)
    assert o.detail.startswith("after 1 retried grasp(s) (max_retries = 1): fingers closed")


def test_a_pass_whose_object_is_lost_during_the_carry_is_the_robots_slip(monkeypatch):
    """pass: held at the grasp and at the lift's end, no longer held on arriving at the
    hand-over pose: the run ends lifted, slipped, "lost during the carry" — not the receiver's
    miss it would be judged as at the plan's end."""
    held = iter([True, True, False])  # closed, lifted, arrived
    monkeypatch.setattr(supervisor_module, "hand_contact", lambda contacts, **k: HandContact(
        0.02, True, True, 2, *((40.0, 40.0) if next(held) else (0.0, 0.0))))
    f = Fixed(task="pass")
    f.advance(0.001)
    motion = SimpleNamespace(t_arrive=0.3, part="handle", hold_duration=1.0)
    plan = SimpleNamespace(regrasp=False, t_grasp_closed=0.1, t_lift_done=0.2, duration=0.8,
                           t_pour=None, R_turn=None, X_WO_place=np.eye(4),
                           t_handover=(0.5, 0.6), handover=motion)
    f.plan(PlanStatus(PlanState.executing, attempt=1, part="usable_area", t_plan=0.01,
                      plan=plan))
    f.advance(0.25)
    assert not f.outcome.final  # closed and lifted, held
    f.advance(0.35)
    o = f.outcome
    assert (o.status, o.reason, o.final) == ("lifted", "slipped", True)
    assert o.detail.startswith("lost during the carry: not held on arriving at the hand-over")
    assert not o.task_outcome.success and "lost during the carry" in o.task_outcome.detail


@pytest.mark.parametrize("t_pour", [None, (0.25, 0.3)])
def test_a_place_whose_object_is_lost_during_the_carry_says_so(monkeypatch, t_pour):
    """A place: held at the grasp, at the lift's end (and at the pour's end), no longer held as
    the descent to the place begins: lifted, slipped, "lost during the carry" — not the distance
    from the place target where the dropped object happened to land."""
    held = iter([True, True] + ([True] if t_pour else []) + [False])
    monkeypatch.setattr(supervisor_module, "hand_contact", lambda contacts, **k: HandContact(
        0.02, True, True, 2, *((40.0, 40.0) if next(held) else (0.0, 0.0))))
    f = Fixed(task="p&pOn")
    f.advance(0.001)
    plan = SimpleNamespace(regrasp=False, t_grasp_closed=0.1, t_lift_done=0.2, duration=0.8,
                           t_pour=t_pour, R_turn=None, X_WO_place=np.eye(4), t_descend=0.4)
    f.plan(PlanStatus(PlanState.executing, attempt=1, part="middle", t_plan=0.01, plan=plan))
    f.advance(0.35)
    assert not f.outcome.final  # closed, lifted (and poured), held
    f.advance(0.45)
    o = f.outcome
    assert (o.status, o.reason, o.final) == ("lifted", "slipped", True)
    assert o.detail.startswith("lost during the carry: not held as the descent to the place")


@pytest.mark.parametrize("max_reseats", [1, 0])
def test_an_object_still_touching_a_pad_once_they_opened_is_reseated_once(monkeypatch,
                                                                          max_reseats):
    """A place: held at the grasp, the lift's end and the descent; at the check after the pads
    opened the object still touches the left pad: the supervisor asks the planner for a re-seat
    (``plan_request.reseats``), waits for the plan that holds it, checks again at its later
    opening (still touching: no second re-seat, max_reseats 1) and the outcome counts it. With
    max_reseats 0 nothing is asked."""
    touch = iter([(True, 40.0)] * 3 + [(True, 0.0)] * 2)
    monkeypatch.setattr(supervisor_module, "hand_contact", lambda contacts, **k: HandContact(
        0.02, *((True, True, 2, 40.0, 40.0) if (t := next(touch, (False, 0.0)))[1]
                else (t[0], False, 1, 0.0, 0.0))))
    monkeypatch.setattr(supervisor_module, "touches_table", lambda contacts, **k: True)
    monkeypatch.setattr(supervisor_module, "placed",
                        lambda *a, **k: (True, "1.0 cm from the target, tilted 0°"))
    f = Fixed(config=SupervisorConfig(planning_start=0.0, period=0.01, planning_timeout=0.5,
                                      max_reseats=max_reseats, release_check_delay=0.02))
    f.advance(0.001)
    plan = SimpleNamespace(regrasp=False, t_grasp_closed=0.1, t_lift_done=0.2, t_descend=0.3,
                           t_opened=0.4, t_place_done=0.45, duration=0.6, t_pour=None,
                           R_turn=None, X_WO_place=np.eye(4))
    f.plan(PlanStatus(PlanState.executing, attempt=1, part="middle", t_plan=0.0, plan=plan))
    f.advance(0.415)
    assert f.request.reseats == 0  # the check comes 0.02 s after the pads opened
    f.advance(0.445)
    assert f.request.reseats == max_reseats
    if max_reseats:
        later = SimpleNamespace(**{**vars(plan), "t_opened": 0.7, "t_place_done": 0.75,
                                   "duration": 0.9})
        f.advance(0.5)  # the planner has not answered: the old plan's end is not judged
        assert not f.outcome.final
        f.plan(PlanStatus(PlanState.executing, attempt=1, part="middle", t_plan=0.0,
                          plan=later, reseats=1))
        f.advance(0.8)
        assert not f.outcome.final and f.request.reseats == 1  # checked again: no second one
    f.advance(1.0)
    o = f.outcome
    assert (o.status, o.reseats, o.as_dict()["reseats"]) == ("placed", max_reseats, max_reseats)
