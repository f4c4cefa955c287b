"""The grasp planner as a Drake system: motion only (paper VI).

`GraspPlanner` plans a pick-and-place for the best candidate it is allowed and reports on
``plan_status`` whether it succeeded or which part failed and why. What to do next (feed the
unreachable part back to the logic as `collision(Part)` evidence and ask again, or give up) is the
`tg_drake.systems.supervisor.Supervisor`'s policy: it tells the planner what to plan through the
``plan_request`` input.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import BasicVector, EventStatus, LeafSystem

from tg_drake.grasping.feasibility import FeasibilityConfig
from tg_drake.planning.planner import PlannerConfig, PlanResult, reseated
from tg_drake.planning.regrasp import plan_task_leg
from tg_drake.planning.task_motion import TaskPlacing
from tg_drake.robot import IIWA_HOME
from tg_drake.scenario import Scenario
from tg_drake.systems.plan_messages import PlanRequest, PlanState, PlanStatus
from tg_drake.types import GraspCandidates, GraspSemantics, SceneDescription

# Without a connected ``plan_request`` the planner makes one attempt with no exclusions.
_ONE_ATTEMPT = PlanRequest(attempt=1)


@dataclass(frozen=True)
class _Memory:
    """The planner's abstract state. Immutable: updates replace it."""

    q_hold: np.ndarray  # (7,) posture held before a plan exists (measured at initialisation)
    attempt: int = 0  # the last request answered
    result: PlanResult | None = None  # the successful planning result
    t_plan: float | None = None  # [s] simulated time the plan starts
    failure: PlanResult | None = None  # the last answered attempt's failed result
    failure_reason: str = ""  # its reason (also for failures without a PlanResult)
    planning_time: float = 0.0  # [s] wall time
    ik_solves: int = 0  # inverse-kinematics solver calls of every request answered
    reseats: int = 0  # re-seat requests answered for the current plan

    def __deepcopy__(self, memo):
        return self  # immutable: the simulator's state copies may share it


class GraspPlanner(LeafSystem):
    """Plans a pick-and-place for the best allowed grasp and commands the arm and the gripper.

    .. pydrake_system::

        name: GraspPlanner
        input_ports:
        - scene_description
        - ranked_grasps
        - iiwa.state
        - plan_request (optional)
        output_ports:
        - iiwa.desired_state
        - wsg.position
        - plan_status

    ``scene_description`` (`SceneDescription`) gives the target (``ranked_grasps.target``) and the
    other objects, whose boxes are obstacles; ``ranked_grasps`` (`GraspCandidates`) are the grasp
    poses, best first; ``iiwa.state`` (14: q, v) is the measured arm state; ``plan_request``
    (`PlanRequest`) says which attempt to plan and which parts to leave out (not connected: one
    attempt, nothing left out).

    At initialisation the measured posture is stored; until a plan exists ``iiwa.desired_state``
    holds it (zero velocity) and ``wsg.position`` holds the gripper open. From `start_time` on, a
    periodic unrestricted update (every `period` seconds) answers a request it has not answered
    yet: it plans for the leading part of ``ranked_grasps`` without the request's excluded parts
    (its candidates best first; `tg_drake.planning.planner.plan_pick_and_place` with one part).
    Once a plan exists, ``iiwa.desired_state`` (q, v) and ``wsg.position`` (opening width [m];
    closing is commanded as width `PlannerConfig.closed_width`, the WSG driver's force limit sets
    the grip) follow it in time from the event at which it was made; a later request is planned
    once the plan is over, from its end posture (the supervisor's next leg: after a
    place-and-regrasp's first leg, `Plan.regrasp`, allowed by `PlanRequest.regrasp`, or after a
    missed grasp, with `PlanRequest.return_home`).

    ``plan_status`` is a `PlanStatus` (from state and time only: feeding it to a supervisor whose
    outputs feed the logic makes no algebraic loop): planning, executing, done or failed,
    with the attempt answered, the chosen part and candidate, or the part that failed and why
    ("failed" stays until the next attempt is answered).
    """

    def __init__(self, *, place_xy, start_time: float = 0.0, period: float = 0.05,
                 config: PlannerConfig | None = None, scenario: Scenario | None = None,
                 placing: TaskPlacing | None = None, surfaces=(), handover=None,
                 feasibility: FeasibilityConfig | None = None):
        """
        Args:
            place_xy: (2,) world xy where the target object's frame origin is placed [m].
            start_time: simulated time of the first planning event [s] (e.g. after perception
                has seen the scene).
            period: spacing of the planning events [s].
            config: the planner's distances, clearances, timing and limits.
            scenario: whose robot and table models the planner's arm plant uses (default: the
                station's).
            placing: the task's placing (`tg_drake.planning.task_motion.task_placing`); None
                places the object at `place_xy`, its orientation kept.
            surfaces: `tg_drake.planning.task_motion.Surface` boxes on the table (obstacles).
            handover: a pass's receiver (`tg_drake.planning.handover.Handover`): the plan hands
                the object over to it; its part comes from the category distribution of the
                optional ``grasp_semantics`` input.
            feasibility: the feasibility stage's config, whose geometric refusals judge the
                grasps of a place-and-regrasp's second leg (default: FeasibilityConfig()).
        """
        super().__init__()
        if len(place_xy) != 2:
            raise ValueError(f"place_xy must be a world (x, y), got {place_xy}")
        if period <= 0 or start_time < 0:
            raise ValueError(f"need period > 0 and start_time >= 0, got {period}, {start_time}")
        self._place_xy = np.asarray(place_xy, float)
        self._config = config or PlannerConfig()
        self._scenario = scenario
        self._placing, self._surfaces = placing, tuple(surfaces)
        self._handover = handover
        self._feasibility = feasibility or FeasibilityConfig()

        self._scene_port = self.DeclareAbstractInputPort(
            "scene_description", AbstractValue.Make(SceneDescription(objects=[], X_WT=np.eye(4))))
        self._grasps_port = self.DeclareAbstractInputPort(
            "ranked_grasps", AbstractValue.Make(_no_candidates()))
        self._state_port = self.DeclareVectorInputPort("iiwa.state", 14)
        self._request_port = self.DeclareAbstractInputPort(
            "plan_request", AbstractValue.Make(PlanRequest()))
        self._semantics_port = self.DeclareAbstractInputPort(  # a pass's receiver part
            "grasp_semantics", AbstractValue.Make(GraspSemantics({}, {}, {}, None)))

        self._memory = self.DeclareAbstractState(
            AbstractValue.Make(_Memory(q_hold=np.asarray(IIWA_HOME, float))))
        self.DeclareInitializationUnrestrictedUpdateEvent(self._initialize)
        self.DeclarePeriodicUnrestrictedUpdateEvent(period, start_time, self._plan)

        # Outputs depend on the state and the time only (never on an input).
        on_state = {self.abstract_state_ticket(self._memory)}
        on_state_and_time = on_state | {self.time_ticket()}
        self._desired_state_port = self.DeclareVectorOutputPort(
            "iiwa.desired_state", 14, self._calc_desired_state,
            prerequisites_of_calc=on_state_and_time)
        self._wsg_port = self.DeclareVectorOutputPort(
            "wsg.position", 1, self._calc_wsg_position, prerequisites_of_calc=on_state_and_time)
        self._status_port = self.DeclareAbstractOutputPort(
            "plan_status", lambda: AbstractValue.Make(PlanStatus(PlanState.planning)),
            self._calc_status, prerequisites_of_calc=on_state_and_time)

    # Port accessors.
    def get_scene_description_input_port(self):
        return self._scene_port

    def get_ranked_grasps_input_port(self):
        return self._grasps_port

    def get_iiwa_state_input_port(self):
        return self._state_port

    def get_plan_request_input_port(self):
        return self._request_port

    def get_iiwa_desired_state_output_port(self):
        return self._desired_state_port

    def get_wsg_position_output_port(self):
        return self._wsg_port

    def get_plan_status_output_port(self):
        return self._status_port

    # Events.
    def _initialize(self, context, state):
        q = np.asarray(self._state_port.Eval(context), float)[:7]
        state.get_mutable_abstract_state(self._memory).set_value(_Memory(q_hold=q.copy()))

    def _request(self, context) -> PlanRequest:
        if not self._request_port.HasValue(context):
            return _ONE_ATTEMPT
        return self._request_port.Eval(context)

    def _plan(self, context, state):
        memory: _Memory = context.get_abstract_state(self._memory).get_value()
        request = self._request(context)
        if (request.attempt == memory.attempt and memory.result is not None
                and request.reseats > memory.reseats):
            state.get_mutable_abstract_state(self._memory).set_value(
                self._reseat(memory, context.get_time() - memory.t_plan, request.reseats))
            return EventStatus.Succeeded()
        if request.attempt <= memory.attempt:
            return EventStatus.DidNothing()
        if memory.result is not None:
            # A plan that is over lets the next request (the supervisor's next leg) be planned,
            # from where it left the arm; until then the plan is followed.
            plan = memory.result.plan
            if context.get_time() - memory.t_plan < plan.duration:
                return EventStatus.DidNothing()
            memory = dataclasses.replace(memory, q_hold=plan.q(plan.duration), result=None,
                                         t_plan=None)
        scene: SceneDescription = self._scene_port.Eval(context)
        grasps: GraspCandidates = self._grasps_port.Eval(context)
        t0 = time.perf_counter()
        memory = dataclasses.replace(memory, attempt=request.attempt, failure=None,
                                     failure_reason="")
        if len(grasps.score) == 0 or not scene.objects:
            memory = dataclasses.replace(
                memory,
                failure_reason="no grasp candidates" if scene.objects else "no objects seen")
        else:
            semantics = (self._semantics_port.Eval(context)
                         if self._semantics_port.HasValue(context) else None)
            result = plan_task_leg(scene, grasps, place_xy=self._place_xy,
                                   q_start=memory.q_hold, config=self._config,
                                   scenario=self._scenario,
                                   exclude_parts=tuple(request.exclude_parts), max_parts=1,
                                   placing=self._placing, surfaces=self._surfaces,
                                   handover=self._handover,
                                   category=semantics.category if semantics else None,
                                   regrasp=request.regrasp,
                                   return_home=request.return_home,
                                   feasibility=self._feasibility)
            memory = dataclasses.replace(memory, ik_solves=memory.ik_solves + result.ik_solves)
            if result.status == "planned":
                memory = dataclasses.replace(memory, result=result, t_plan=context.get_time(),
                                             reseats=0)
            else:
                memory = dataclasses.replace(memory, failure=result,
                                             failure_reason=result.reason)
        memory = dataclasses.replace(
            memory, planning_time=memory.planning_time + time.perf_counter() - t0)
        state.get_mutable_abstract_state(self._memory).set_value(memory)
        return EventStatus.Succeeded()

    def _reseat(self, memory: _Memory, t: float, reseats: int) -> _Memory:
        """The plan with a re-seat inserted at plan time t when its pads stand open at the place
        then; later than that the request is answered with the plan unchanged."""
        plan = memory.result.plan
        if plan.pads_open_at_place(t):
            plan = reseated(plan, t, self._config)
        return dataclasses.replace(memory, result=dataclasses.replace(memory.result, plan=plan),
                                   reseats=reseats)

    # Outputs.
    def _memory_of(self, context) -> _Memory:
        return context.get_abstract_state(self._memory).get_value()

    def _calc_desired_state(self, context, output: BasicVector):
        memory = self._memory_of(context)
        if memory.result is None:
            output.SetFromVector(np.concatenate([memory.q_hold, np.zeros(7)]))
            return
        t = context.get_time() - memory.t_plan
        plan = memory.result.plan
        output.SetFromVector(np.concatenate([plan.q(t), plan.v(t)]))

    def _calc_wsg_position(self, context, output: BasicVector):
        memory = self._memory_of(context)
        if memory.result is None:
            output.SetAtIndex(0, self._config.open_width)
            return
        output.SetAtIndex(0, memory.result.plan.width(context.get_time() - memory.t_plan))

    def _calc_status(self, context, output):
        memory = self._memory_of(context)
        common = dict(attempt=memory.attempt, planning_time=memory.planning_time,
                      ik_solves=memory.ik_solves, reseats=memory.reseats)
        if memory.result is not None:
            plan = memory.result.plan
            done = context.get_time() - memory.t_plan >= plan.duration
            output.set_value(PlanStatus(PlanState.done if done else PlanState.executing,
                                        part=plan.part, candidate=plan.candidate,
                                        X_WG=plan.X_WG_grasp, t_plan=memory.t_plan, plan=plan,
                                        **common))
            return
        if memory.failure_reason:
            failure = memory.failure
            output.set_value(PlanStatus(
                PlanState.failed,
                unreachable_parts=tuple(failure.unreachable_parts) if failure else (),
                picked_parts=tuple(failure.picked_parts) if failure else (),
                reason=memory.failure_reason, **common))
            return
        output.set_value(PlanStatus(PlanState.planning, **common))


def _no_candidates() -> GraspCandidates:
    return GraspCandidates(X_WG=np.zeros((0, 4, 4)), parts=np.zeros(0, int), p_part=np.zeros(0),
                           p_local=np.zeros(0), score=np.zeros(0))
