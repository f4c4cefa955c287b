"""The closed loop's one owner: the logic's veto, the re-query policy, waiting for plans and the
execution monitor, with the run's `Outcome` on an output port.

A composed diagram (`tg_drake.diagram.add_pipeline`) and `tg-drake run` behave the same because
every decision that spans stages is taken here, in simulated time, from port values:

1. **Gate** (at `SupervisorConfig.planning_start`, and again after every re-query): perception
   saw an object at the target; the logic does not rule grasping out (P(some part is grasped) ≥
   `min_grasp_probability`, some part with non-zero probability); some pre-grasp hypothesis has a
   non-zero score. Then the planner is asked for a plan (``plan_request``, attempt n).
2. **Re-query**: a failed attempt whose part has no pickable candidate makes that part
   `collision(Part)` evidence on ``collisions`` (read by the logic); after at most
   `max_requeries` re-queries, or when no part is blamed, the run fails as "unreachable", with the
   first failure's reason kept in the detail.
3. **Monitor**: at the plan's key times (the first check at or after each): both pads hold the
   object when the gripper has closed (else "missed"), the object rose with the gripper during the
   lift (else "slipped"), and at the end it stands let go at the place target (else "lifted").
4. **Task check** (when the scenario gives a task): at the end, the task's judge
   (`tg_drake.tasks.judge`) on the object's simulated pose, its contacts and the contents'
   counts gives `Outcome.task_outcome`; a run that ended before the end of its plan gets a failed
   task outcome saying why.
5. **Legs** (place-and-regrasp, p&pIn*): for a given p&pIn* task, while fewer than
   `SupervisorConfig.max_regrasps` legs are done, a plan request allows a first leg
   (`PlanRequest.regrasp`). A plan that ends with the object put down in an intermediate pose
   (`Plan.regrasp`) is monitored like any other; placed,
   the leg is recorded (`Outcome.legs`), the supervisor asks perception to look again (the
   ``perception_request`` counter), waits for the new latch (``perception_status.request``),
   then runs the gate and asks for the next leg's plan from the new scene, with the same task.
   The final leg's outcome and task outcome are the run's.
6. **Retries** (`SupervisorConfig.max_retries`, 0 = off): while retries are left, every plan
   ends with the arm back at its start (`PlanRequest.return_home`); a missed grasp or a failed
   lift is then recorded as a leg, and once that plan is over, perception looks again and the
   next leg is planned from the new scene instead of ending the run.
"""


import dataclasses
import enum
from dataclasses import dataclass, field

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import ContactResults
from pydrake.systems.framework import EventStatus, LeafSystem

from tg_drake.errors import (
    GraspingError,
    KernelError,
    PerceptionError,
    PlanningError,
    RuleError,
    SimulationError,
    TgDrakeError,
)
from tg_drake.grasping.feasibility import why_no_pose
from tg_drake.outcome import (
    HandGeometries,
    contact_pairs,
    contact_points,
    contacts_of,
    hand_contact,
    part_touched,
    placed,
    touches_table,
)
from tg_drake.scenario import SupervisorConfig
from tg_drake.systems.plan_messages import PlanRequest, PlanState, PlanStatus
from tg_drake.tasks.judge import (
    REST_POSE_OF_TASK,
    judge_on_surface,
    judge_pass,
    judge_pour,
    judge_rest_pose,
    rest_pose,
)
from tg_drake.tasks.outcome import TaskOutcome
from tg_drake.types import (
    PART_LABELS,
    GraspCandidates,
    GraspSemantics,
    PerceptionStatus,
    SceneDescription,
)


class Status(enum.StrEnum):
    """``Outcome.status`` (compares equal to its value)."""

    pending = "pending"  # not final yet
    placed = "placed"
    lifted = "lifted"
    grasped = "grasped"
    failed = "failed"


class Reason(enum.StrEnum):
    """``Outcome.reason``: why a run failed or fell short of placing ("" when placed)."""

    none = ""
    unreachable = "unreachable"
    would_not_hold = "would_not_hold"  # reachable, but no grasp on the parts left would hold
    perception = "perception"
    logic = "logic"
    slipped = "slipped"
    missed = "missed"
    simulation = "simulation"
    timeout = "timeout"


OUTCOME_STATUSES = tuple(s.value for s in Status if s is not Status.pending)  # final statuses
FAILURE_REASONS = tuple(r.value for r in Reason if r is not Reason.none)

# The failure reason a stage's error stands for.
REASON_OF_ERROR = ((PerceptionError, Reason.perception), (KernelError, Reason.perception),
                   (RuleError, Reason.logic), (GraspingError, Reason.logic),
                   (PlanningError, Reason.unreachable), (SimulationError, Reason.simulation))


def reason_of(error: TgDrakeError) -> Reason:
    return next((r for cls, r in REASON_OF_ERROR if isinstance(error, cls)), Reason.simulation)


@dataclass(frozen=True)
class Outcome:
    """Value of the ``outcome`` output: what the run came to, final once `final` is True."""

    status: Status = Status.pending
    reason: Reason = Reason.none  # for "failed" or a partial success; none when placed
    detail: str = ""  # a human-readable explanation (while pending: what the supervisor waits for)
    reachable_parts: tuple = ()  # the part a plan was made for
    unreachable_parts: tuple = ()  # parts given to the logic as collision(Part) evidence
    requeries: int = 0  # how often the logic was asked again with new collision evidence
    task_outcome: TaskOutcome | None = None  # the task's physical check (None: no task given)
    legs: tuple = ()  # the legs done before the final one (place-and-regrasp, retries): a dict
    # each (part, ended: placed / missed / slipped, placed_pose, xy [m] or None, t_end [s])
    reseats: int = 0  # re-seats at the place: the object still touched a pad once they had opened

    @property
    def final(self) -> bool:
        return self.status is not Status.pending

    def as_dict(self) -> dict:
        """The JSON form (result.json's ``outcome``)."""
        return {"status": self.status.value, "reason": self.reason.value, "detail": self.detail,
                "reachable_parts": list(self.reachable_parts),
                "unreachable_parts": list(self.unreachable_parts), "requeries": self.requeries,
                "task_outcome": (self.task_outcome.as_dict() if self.task_outcome is not None
                                 else None),
                "legs": [dict(leg) for leg in self.legs], "reseats": self.reseats}


def outcome_of_error(error: Exception, *, pending: Outcome | None = None) -> Outcome:
    """The failed outcome of an error raised while simulating (a stage's TgDrakeError, or a
    RuntimeError of the simulation itself), keeping the closed loop's parts and count."""
    pending = pending or Outcome()
    if isinstance(error, TgDrakeError):
        reason, detail = reason_of(error), str(error)
    else:
        reason, detail = Reason.simulation, f"the simulation failed: {error}"
    task = pending.task_outcome
    if task is not None:
        task = TaskOutcome(task.task, False, {}, f"not done: the run failed ({reason}): {detail}")
    return dataclasses.replace(pending, status=Status.failed, reason=reason, detail=detail,
                               task_outcome=task)


@dataclass(frozen=True)
class MonitorModel:
    """What the execution monitor needs to know about the plant's model (read once, before
    simulating): the geometry ids of the target, fingers and table and the gripper's body index
    (`geometries`), the target's body index in ``body_poses`` and its box centre in its frame [m];
    for the task check: the table frame, whether the target is a tool, and the collision
    geometry ids of each of the scenario's surfaces (by name; they belong to the table)."""

    geometries: HandGeometries  # its `gripper`: the WSG body's index in ``body_poses``
    object_body: int
    p_OC: tuple = (0.0, 0.0, 0.0)
    X_WT: tuple = tuple(map(tuple, np.eye(4)))  # 4×4 table frame, as nested tuples
    is_tool: bool = False
    surfaces: tuple = ()  # (name, frozenset of GeometryId) per surface
    receiver: HandGeometries | None = None  # pass: the target, the receiver's fingers, the table
    # pass: the target's labelled mesh, (vertices (V, 3) in its frame [m], part labels (V,)): the
    # part the receiver holds is measured on it (ground truth of the execution, like the poses)
    part_vertices: tuple | None = field(default=None, compare=False)

    @classmethod
    def from_plant(cls, plant, *, object_body, wsg_instance, table_instance,
                   p_OC=(0.0, 0.0, 0.0), X_WT=None, is_tool: bool = False,
                   surfaces=(), receiver_instance=None, part_vertices=None
                   ) -> "MonitorModel":
        """`surfaces`: names of the surfaces' bodies in the table's model instance;
        `receiver_instance`: a pass's receiver WSG (tg_drake.receiver), or None;
        `part_vertices`: (vertices, labels) of the target's mesh, or None."""
        surface_ids = tuple(
            (name, frozenset(plant.GetCollisionGeometriesForBody(
                plant.GetBodyByName(body, table_instance)))) for name, body in surfaces)
        return cls(HandGeometries.from_plant(plant, object_body=object_body,
                                             wsg_instance=wsg_instance,
                                             table_instance=table_instance),
                   int(object_body.index()),
                   tuple(float(v) for v in p_OC),
                   tuple(map(tuple, np.eye(4) if X_WT is None else np.asarray(X_WT, float))),
                   bool(is_tool), surface_ids,
                   None if receiver_instance is None else HandGeometries.from_plant(
                       plant, object_body=object_body, wsg_instance=receiver_instance,
                       table_instance=table_instance), part_vertices)


class Phase(enum.StrEnum):
    gate = "gate"  # the next check runs the gate (at the start, and after a re-query)
    planning = "planning"  # waiting for the planner's answer to the current attempt
    executing = "executing"  # following the plan, monitoring its key times
    looking = "looking"  # a regrasp leg is placed: waiting for perception to look again
    done = "done"  # the outcome is final


@dataclass(frozen=True)
class _Memory:
    """The supervisor's abstract state. Immutable: updates replace it."""

    phase: Phase = Phase.gate
    attempt: int = 0  # the last plan attempt requested
    collisions: tuple = ()  # parts given to the logic as collision(Part) evidence
    no_hold: tuple = ()  # parts given to the logic as no_hold(Part) evidence
    requeries: int = 0
    failures: tuple = ()  # (part or None, reason) of every failed attempt, in order
    status: PlanStatus | None = None  # the planner's answer with the plan being executed
    checks_passed: int = 0  # execution checks passed: 1 grasp closed, 2 lift done, 3 the pour
    # held over the bowl (pour plans) or arrived at the hand-over still held (pass), 4 (pass)
    # the robot let go; a place: still held as the descent begins (3, or 4 after a pour)
    z_G_grasped: float = 0.0  # [m] gripper body height when the grasp closed
    z_O_grasped: float = 0.0  # [m] object height when the grasp closed
    X_WO_picked: RigidTransform | None = None  # object pose when the plan started
    z_released: tuple = ()  # [m] pass: the object's heights from the robot's release on
    t_released: float | None = None  # [s] pass: simulated time of the robot's release
    held_at_pour: bool = False  # the gripper held the container at the end of the pour
    outcome: Outcome | None = None  # the final outcome
    looks: int = 0  # perception_request: how often perception was asked to look again
    legs: tuple = ()  # Outcome.legs: the regrasp legs done
    t_leg: float | None = None  # [s] when the current leg's gate began (None: planning_start)
    target_xy: tuple = ()  # world xy [m] where the last regrasp leg put the target (its box
    # centre, as planned); () before any
    retries: int = 0  # legs ended by a missed grasp or a failed lift, looked at again
    look_after: float | None = None  # [s] ask perception to look once this time has passed (the
    # end of a plan whose grasp failed)
    reseats: int = 0  # re-seats asked of the planner for the plan being executed
    reseats_run: int = 0  # re-seats asked for in the whole run (Outcome.reseats)

    def __deepcopy__(self, memo):
        return self  # immutable: the simulator's state copies may share it


class Supervisor(LeafSystem):
    """Gates, re-queries, waits for plans and monitors the execution; publishes the outcome.

    .. pydrake_system::

        name: Supervisor
        input_ports:
        - scene_description
        - grasp_semantics
        - ranked_grasps
        - plan_status
        - wsg.state
        - body_poses
        - contact_results
        - perception_status (optional)
        output_ports:
        - collisions
        - no_hold
        - plan_request
        - outcome
        - dispenser_command
        - perception_request
        - target_xy

    ``scene_description`` (`SceneDescription`), ``grasp_semantics`` (`GraspSemantics`) and
    ``ranked_grasps`` (`GraspCandidates`) are read at gate checks only; ``plan_status``
    (`PlanStatus`) while waiting for a plan; ``wsg.state`` (4: finger q, v), ``body_poses``
    (world poses of the plant's bodies) and ``contact_results`` (`ContactResults`) at the plan's
    key times only. A periodic unrestricted update every `SupervisorConfig.period` seconds from
    `planning_start` moves through the phases gate → planning → executing → done (module doc);
    a check that changes nothing leaves the state untouched. A stage's error raised during a gate
    check (`TgDrakeError`) ends the run as failed with that stage's reason.

    Outputs depend on the state only: ``collisions`` (tuple of part names, for the logic's
    ``collisions`` input), ``no_hold`` (the parts on which the feasibility stage found no grasp
    that would hold, `GraspCandidates.unholdable_parts`, for the logic's ``no_hold`` input),
    ``plan_request`` (`PlanRequest`: the attempt to plan and the parts to
    leave out, for the planner) and ``outcome`` (`Outcome`; `Outcome.final` once decided);
    ``dispenser_command`` (1-vector: 1 opens the station's dispenser) on the state and the time.
    Legs (module doc, 5): ``perception_request`` (int counter, for both perception systems'
    ``perception_request`` input) grows by one after each regrasp leg; ``perception_status``
    (`PerceptionStatus`) is read while looking; ``target_xy`` (tuple: () or the world xy where
    the last regrasp leg put the target) tells the target selector where the target is now.
    """

    def __init__(self, *, config: SupervisorConfig | None = None, model: "MonitorModel",
                 task: str = "", place_on: str = "", pour_into: str = "", container: str = "",
                 count_contents=None, dispense_duration: float = 0.0):
        """`task`: the scenario's given task ("" = inferred: no task check); `place_on`: the
        surface p&pOn places the object on; `pour_into`: the instance name of the bowl
        (pourOut); `container`: the target's instance name (pourIn's receiving vessel);
        `count_contents`: body_poses → {place: number of spheres} (the keys of
        `tg_drake.tasks.contents.count_contents`), None when the station has no contents;
        `dispense_duration` [s]: pourIn opens the dispenser (``dispenser_command`` 1) this long
        from the start of the plan's hold under it."""
        super().__init__()
        self._config = config or SupervisorConfig()
        self._config.validate()
        self._model = model
        self._task, self._place_on = task, place_on
        self._pour_into, self._container = pour_into, container
        self._count_contents = count_contents
        self._dispense_duration = float(dispense_duration)

        self._scene_port = self.DeclareAbstractInputPort(
            "scene_description", AbstractValue.Make(SceneDescription(objects=[], X_WT=np.eye(4))))
        self._semantics_port = self.DeclareAbstractInputPort(
            "grasp_semantics", AbstractValue.Make(GraspSemantics({}, {}, {}, None)))
        self._grasps_port = self.DeclareAbstractInputPort(
            "ranked_grasps", AbstractValue.Make(GraspCandidates(
                X_WG=np.zeros((0, 4, 4)), parts=np.zeros(0, int), p_part=np.zeros(0),
                p_local=np.zeros(0), score=np.zeros(0))))
        self._status_port = self.DeclareAbstractInputPort(
            "plan_status", AbstractValue.Make(PlanStatus(PlanState.planning)))
        self._wsg_port = self.DeclareVectorInputPort("wsg.state", 4)
        self._receiver_port = self.DeclareVectorInputPort("receiver.state", 4)  # pass only
        self._poses_port = self.DeclareAbstractInputPort(
            "body_poses", AbstractValue.Make([RigidTransform()]))
        self._contacts_port = self.DeclareAbstractInputPort(
            "contact_results", AbstractValue.Make(ContactResults()))
        self._perception_port = self.DeclareAbstractInputPort(
            "perception_status", AbstractValue.Make(PerceptionStatus(ok=False)))

        self._memory = self.DeclareAbstractState(AbstractValue.Make(_Memory()))
        self.DeclarePeriodicUnrestrictedUpdateEvent(self._config.period,
                                                    self._config.planning_start, self._check)

        on_state = {self.abstract_state_ticket(self._memory)}
        self._collisions_port = self.DeclareAbstractOutputPort(
            "collisions", lambda: AbstractValue.Make(()), self._calc_collisions,
            prerequisites_of_calc=on_state)
        self._no_hold_port = self.DeclareAbstractOutputPort(
            "no_hold", lambda: AbstractValue.Make(()), self._calc_no_hold,
            prerequisites_of_calc=on_state)
        self._request_port = self.DeclareAbstractOutputPort(
            "plan_request", lambda: AbstractValue.Make(PlanRequest()), self._calc_request,
            prerequisites_of_calc=on_state)
        self._outcome_port = self.DeclareAbstractOutputPort(
            "outcome", lambda: AbstractValue.Make(Outcome()), self._calc_outcome,
            prerequisites_of_calc=on_state)
        self._dispenser_port = self.DeclareVectorOutputPort(
            "dispenser_command", 1, self._calc_dispenser,
            prerequisites_of_calc=on_state | {self.time_ticket()})
        self._look_port = self.DeclareAbstractOutputPort(
            "perception_request", lambda: AbstractValue.Make(0),
            lambda context, output: output.set_value(self._memory_of(context).looks),
            prerequisites_of_calc=on_state)
        self._target_xy_port = self.DeclareAbstractOutputPort(
            "target_xy", lambda: AbstractValue.Make(()),
            lambda context, output: output.set_value(self._memory_of(context).target_xy),
            prerequisites_of_calc=on_state)

    @property
    def config(self) -> SupervisorConfig:
        return self._config

    # Port accessors.
    def get_scene_description_input_port(self):
        return self._scene_port

    def get_grasp_semantics_input_port(self):
        return self._semantics_port

    def get_ranked_grasps_input_port(self):
        return self._grasps_port

    def get_plan_status_input_port(self):
        return self._status_port

    def get_wsg_state_input_port(self):
        return self._wsg_port

    def get_body_poses_input_port(self):
        return self._poses_port

    def get_contact_results_input_port(self):
        return self._contacts_port

    def get_perception_status_input_port(self):
        return self._perception_port

    def get_perception_request_output_port(self):
        return self._look_port

    def get_target_xy_output_port(self):
        return self._target_xy_port

    def get_collisions_output_port(self):
        return self._collisions_port

    def get_no_hold_output_port(self):
        return self._no_hold_port

    def get_plan_request_output_port(self):
        return self._request_port

    def get_outcome_output_port(self):
        return self._outcome_port

    def get_dispenser_command_output_port(self):
        return self._dispenser_port

    # The periodic check.
    def _check(self, context, state):
        memory: _Memory = context.get_abstract_state(self._memory).get_value()
        if memory.phase is Phase.done:
            return EventStatus.DidNothing()
        try:
            if memory.phase is Phase.gate:
                new = self._gate(context, memory)
            elif memory.phase is Phase.planning:
                new = self._await_plan(context, memory)
            elif memory.phase is Phase.looking:
                new = self._await_look(context, memory)
            else:
                new = self._monitor(context, memory)
        except TgDrakeError as e:
            new = self._finish(memory, Status.failed, reason_of(e), str(e))
        if new is memory:
            return EventStatus.DidNothing()
        state.get_mutable_abstract_state(self._memory).set_value(new)
        return EventStatus.Succeeded()

    def _finish(self, memory: _Memory, status: Status, reason: Reason, detail: str,
                task_outcome: TaskOutcome | None = None, **changes) -> _Memory:
        memory = dataclasses.replace(memory, **changes)
        if memory.legs and status is Status.failed:
            regrasps = len(memory.legs) - memory.retries
            done = ([f"{regrasps} place-and-regrasp leg(s) (max_regrasps = "
                     f"{self._config.max_regrasps})"] if regrasps else [])
            done += ([f"{memory.retries} retried grasp(s) (max_retries = "
                      f"{self._config.max_retries})"] if memory.retries else [])
            detail = f"after {' and '.join(done)}: {detail}"
        reachable = (memory.status.part,) if memory.status is not None else ()
        if task_outcome is None and self._task:
            why = f"{status}" + (f" ({reason})" if reason else "")
            task_outcome = TaskOutcome(self._task, False, {},
                                       f"not done: the run ended {why}: {detail}")
            # pass: a plan refused for its hand-over says so (the receiver's reach or grasp).
            handover = next((r[r.index("hand-over:"):] for _, r in memory.failures
                             if "hand-over:" in r), "")
            if self._task == "pass" and handover:
                task_outcome = TaskOutcome(self._task, False, {"handed_over": False},
                                           f"not done: {handover}; the run ended {why}: {detail}")
        return dataclasses.replace(memory, phase=Phase.done, outcome=Outcome(
            status, reason, detail, reachable_parts=reachable,
            unreachable_parts=memory.collisions, requeries=memory.requeries,
            task_outcome=task_outcome, legs=memory.legs, reseats=memory.reseats_run))

    def _gate(self, context, memory: _Memory) -> _Memory:
        scene: SceneDescription = self._scene_port.Eval(context)
        if not scene.objects:
            return self._finish(memory, Status.failed, Reason.perception,
                                "perception found no object on the table")
        if scene.target is None:
            return self._finish(memory, Status.failed, Reason.perception,
                                "perception found no object at the target's position")
        # After a re-query the logic answers with the collision evidence: a veto then comes
        # from the parts found unreachable.
        reason, told = Reason.logic, ""
        if memory.collisions:
            reason = Reason.unreachable
            # Why it cannot be reached: the planner's words (the logic only hears the part).
            told = (f", told {', '.join(memory.collisions)} cannot be reached"
                    + (f": {_why(memory.failures)}" if memory.failures else ""))
        if memory.no_hold:
            reason = Reason.unreachable if memory.collisions else Reason.would_not_hold
            told += f", told no grasp on {', '.join(memory.no_hold)} would hold"
        semantics: GraspSemantics = self._semantics_port.Eval(context)
        task = semantics.given_task or "inferred"
        if not semantics.part or max(semantics.part.values()) <= 0:
            return self._finish(memory, Status.failed, reason,
                                f"the logic ruled every grasp out (task {task}{told})")
        p, p_min = semantics.grasp_probability, self._config.min_grasp_probability
        if p < p_min:
            return self._finish(memory, Status.failed, reason,
                                "the logic rules grasping out: P(some part is grasped) = "
                                f"{p:.3f} < {p_min} (task {task}{told})")
        grasps: GraspCandidates = self._grasps_port.Eval(context)
        if len(grasps.score) == 0 or not np.any(np.asarray(grasps.score) > 0):
            if grasps.unholdable_parts:
                reason = Reason.would_not_hold
                told += f"; no grasp on {', '.join(grasps.unholdable_parts)} would hold"
            why = why_no_pose(grasps, semantics.part)
            return self._finish(memory, Status.failed, reason,
                                f"no pre-grasp hypothesis with a non-zero score"
                                f"{': ' + why if why else ''}{told}")
        return dataclasses.replace(memory, phase=Phase.planning, attempt=memory.attempt + 1)

    def _await_plan(self, context, memory: _Memory) -> _Memory:
        status: PlanStatus = self._status_port.Eval(context)
        if status.attempt >= memory.attempt and status.status in (PlanState.executing,
                                                                  PlanState.done):
            poses = self._poses_port.Eval(context)
            return dataclasses.replace(memory, phase=Phase.executing, status=status,
                                       X_WO_picked=poses[self._model.object_body], reseats=0)
        if status.attempt >= memory.attempt and status.status is PlanState.failed:
            return self._after_failure(memory, status, self._grasps_port.Eval(context))
        start = self._config.planning_start if memory.t_leg is None else memory.t_leg
        deadline = start + self._config.planning_timeout
        if context.get_time() >= deadline:
            return self._finish(memory, Status.failed, Reason.timeout,
                                f"no plan within planning_timeout = "
                                f"{self._config.planning_timeout} s (attempt {memory.attempt})")
        return memory

    def _after_failure(self, memory: _Memory, status: PlanStatus,
                       grasps: GraspCandidates) -> _Memory:
        failures = memory.failures + ((status.failed_part, status.reason),)
        why = _why(failures)
        told = memory.collisions + memory.no_hold
        new = tuple(p for p in status.unreachable_parts if p not in told)
        # Parts the feasibility stage found no holding grasp on: not unreachable, told apart.
        held = tuple(p for p in grasps.unholdable_parts if p not in told and p not in new)
        # No part blamed for reach, none picked but then not placed (a place, pour or hand-over
        # out of reach), and some would not hold: the run fails for holding.
        holding = (not status.unreachable_parts and not status.picked_parts
                   and bool(memory.no_hold + held))
        reason = Reason.would_not_hold if holding else Reason.unreachable
        if holding:
            why = f"no grasp on {', '.join(memory.no_hold + held)} would hold; {why}"
        if not new and not held:  # nothing new to tell the logic
            return self._finish(memory, Status.failed, reason, why, failures=failures)
        collisions, no_hold = memory.collisions + new, memory.no_hold + held
        if memory.requeries >= self._config.max_requeries:
            return self._finish(memory, Status.failed, reason,
                                f"gave up after {memory.requeries} re-queries; {why}",
                                failures=failures, collisions=collisions, no_hold=no_hold)
        return dataclasses.replace(memory, phase=Phase.gate, failures=failures,
                                   collisions=collisions, no_hold=no_hold,
                                   requeries=memory.requeries + 1)

    def _monitor(self, context, memory: _Memory) -> _Memory:
        if memory.status.reseats < memory.reseats:  # a re-seat asked for: wait for its plan
            status: PlanStatus = self._status_port.Eval(context)
            if status.reseats < memory.reseats:
                return memory
            memory = dataclasses.replace(memory, status=status)
        plan, t_plan = memory.status.plan, memory.status.t_plan
        t = context.get_time() - t_plan
        pour = () if plan.t_pour is None else (plan.t_pour[1],)
        t_handover = getattr(plan, "t_handover", None)  # plans without a hand-over may lack it
        # pass: the robot has arrived at the hand-over pose (it must still hold the object),
        # then it has let go
        handover = () if t_handover is None else (
            max(plan.handover.t_arrive, plan.t_lift_done), t_handover[1])
        # a place: the descent begins (it must still hold the object)
        t_descend = getattr(plan, "t_descend", None)
        carried = () if handover or t_descend is None else (t_descend,)
        # a place: the pads stand open at the place (the object must have come free of them)
        t_opened = getattr(plan, "t_opened", None)
        opened = (() if not carried or t_opened is None
                  else (t_opened + self._config.release_check_delay,))
        key_times = (plan.t_grasp_closed, plan.t_lift_done, *pour, *handover, *carried,
                     *opened, plan.duration)
        key_time = key_times[memory.checks_passed]
        if memory.t_released is not None and t < key_time:  # pass: the height while held
            X = self._poses_port.Eval(context)[self._model.object_body]
            z = X.multiply(np.array(self._model.p_OC))[2]  # its box centre
            return dataclasses.replace(memory, z_released=memory.z_released + (float(z),))
        if t < key_time:
            return memory
        contacts = self._contacts_port.Eval(context)
        poses = self._poses_port.Eval(context)
        hand = hand_contact(contacts, wsg_q=self._wsg_port.Eval(context)[:2],
                            geometries=self._model.geometries,
                            R_WG=poses[self._model.geometries.gripper].rotation())
        X_WO = poses[self._model.object_body]
        z_G = poses[self._model.geometries.gripper].translation()[2]
        if memory.checks_passed == 0:  # the gripper has closed
            if not hand.held:
                why = f"fingers closed without holding the object ({hand.describe()})"
                if memory.retries < self._config.max_retries:
                    return self._retry(context, memory, plan, X_WO, "missed")
                return self._finish(memory, Status.failed, Reason.missed, why)
            return dataclasses.replace(memory, checks_passed=1, z_G_grasped=z_G,
                                       z_O_grasped=X_WO.translation()[2])
        if memory.checks_passed == 1:  # the lift is done
            rise = X_WO.translation()[2] - memory.z_O_grasped
            gripper_rise = z_G - memory.z_G_grasped
            if not hand.held or rise < self._config.min_rise_ratio * gripper_rise:
                if memory.retries < self._config.max_retries:
                    return self._retry(context, memory, plan, X_WO, "slipped")
                # Say which test failed: the one rule of holding (outcome.is_held: it pushes
                # both pads apart) or the rise it should have made with the gripper.
                why = ("" if hand.held else f"not held at the lift's end ({hand.describe()}); ")
                return self._finish(memory, Status.grasped, Reason.slipped,
                                    f"{why}the object rose {rise * 100:.1f} cm while the gripper "
                                    f"rose {gripper_rise * 100:.1f} cm")
            return dataclasses.replace(memory, checks_passed=2)
        if memory.checks_passed == 2 and pour:  # the pour's hold is over
            return dataclasses.replace(memory, checks_passed=3, held_at_pour=hand.held)
        if carried and memory.checks_passed == 2 + len(pour):  # over the place, descending
            if not hand.held:
                return self._finish(memory, Status.lifted, Reason.slipped,
                                    f"lost during the carry: not held as the descent to the "
                                    f"place began ({hand.describe()})")
            return dataclasses.replace(memory, checks_passed=memory.checks_passed + 1)
        if opened and memory.checks_passed == 3 + len(pour):  # the pads stand open at the place
            if (hand.left or hand.right) and memory.reseats < self._config.max_reseats:
                # Still touching a pad, the retreat could drag it along: the planner re-seats it
                # (closes on it where it stands, opens again), then this check runs again.
                return dataclasses.replace(memory, reseats=memory.reseats + 1,
                                           reseats_run=memory.reseats_run + 1)
            return dataclasses.replace(memory, checks_passed=memory.checks_passed + 1)
        if memory.checks_passed == 2 and handover:  # pass: arrived at the hand-over pose
            if not hand.held:
                return self._finish(memory, Status.lifted, Reason.slipped,
                                    f"lost during the carry: not held on arriving at the "
                                    f"hand-over ({hand.describe()})")
            return dataclasses.replace(memory, checks_passed=3)
        if memory.checks_passed == 3 and handover:  # pass: the robot has let go
            return dataclasses.replace(memory, checks_passed=4, t_released=context.get_time(),
                                       z_released=(float(X_WO.multiply(
                                           np.array(self._model.p_OC))[2]),))
        if handover:  # pass: the receiver has held it alone to the end of the plan
            task = self._judge_pass(context, memory, contacts, hand, poses)
            detail = ("handed over: " if task.success else "let go at the hand-over; ") \
                + task.detail
            return self._finish(memory, Status.lifted, Reason.none, detail, task)
        # The plan is over: let go, the table carries the object (a pad may still brush it).
        if not np.all(np.isfinite(X_WO.GetAsMatrix4())):
            return self._finish(memory, Status.failed, Reason.simulation,
                                "the simulation diverged")
        on_table = touches_table(contacts, geometries=self._model.geometries)
        X_WO_expected = memory.X_WO_picked
        if plan.R_turn is not None:  # the plan turns the object into another resting pose
            X_WO_expected = RigidTransform(
                RotationMatrix(np.asarray(plan.R_turn)) @ memory.X_WO_picked.rotation(),
                memory.X_WO_picked.translation())
        ok, detail = placed(X_WO_expected, X_WO, plan.X_WO_place[:2, 3],
                            released=on_table and not hand.held, p_OC=self._model.p_OC)
        if plan.regrasp:
            return self._after_leg(context, memory, plan, X_WO, ok, detail)
        task = self._task_check(X_WO, plan, contacts, released=not hand.held, poses=poses,
                                held_at_pour=memory.held_at_pour)
        if ok:
            return self._finish(memory, Status.placed, Reason.none, detail, task)
        return self._finish(memory, Status.lifted, Reason.slipped, detail, task)

    # Legs (place-and-regrasp).
    def _after_leg(self, context, memory: _Memory, plan, X_WO: RigidTransform, ok: bool,
                   detail: str) -> _Memory:
        """A regrasp leg's plan is over: placed, it is recorded and perception is asked to look
        again; else the run ends as for a plan that did not place."""
        if not ok:
            task = (TaskOutcome(self._task, False, {}, "not done: the object was not placed "
                                f"in its intermediate pose: {detail}") if self._task else None)
            return self._finish(memory, Status.lifted, Reason.slipped,
                                f"place-and-regrasp leg {len(memory.legs) + 1}: {detail}", task)
        xy = tuple(round(float(v), 4) for v in plan.X_WO_place[:2, 3])
        return dataclasses.replace(self._next_leg(context, memory, X_WO, "placed", xy),
                                   looks=memory.looks + 1, target_xy=xy)

    def _retry(self, context, memory: _Memory, plan, X_WO: RigidTransform, ended: str
               ) -> _Memory:
        """A missed grasp or a failed lift with retries left: recorded as a leg; perception is
        asked to look again once the plan (which ends with the arm back at its start) is over."""
        return dataclasses.replace(self._next_leg(context, memory, X_WO, ended, None),
                                   retries=memory.retries + 1,
                                   look_after=memory.status.t_plan + plan.duration)

    def _next_leg(self, context, memory: _Memory, X_WO: RigidTransform, ended: str, xy
                  ) -> _Memory:
        """The leg that ends now recorded (`Outcome.legs`), the state made ready for the next
        (a new scene: no collision or no-hold evidence), looking."""
        leg = (("part", memory.status.part), ("ended", ended),
               ("placed_pose", rest_pose(X_WO.GetAsMatrix4(), np.array(self._model.X_WT),
                                         is_tool=self._model.is_tool)),
               ("xy", None if xy is None else list(xy)),
               ("t_end", round(float(context.get_time()), 3)))
        return dataclasses.replace(memory, phase=Phase.looking, legs=memory.legs + (leg,),
                                   status=None, checks_passed=0, held_at_pour=False,
                                   collisions=(), no_hold=(), failures=(),
                                   t_leg=context.get_time())

    def _await_look(self, context, memory: _Memory) -> _Memory:
        """Waits for perception to serve the latest request, then runs the gate again (after a
        failed grasp, asks for the look once its plan is over)."""
        if memory.look_after is not None:
            if context.get_time() < memory.look_after:
                return memory
            memory = dataclasses.replace(memory, looks=memory.looks + 1, look_after=None,
                                         t_leg=context.get_time())
        if not self._perception_port.HasValue(context):
            return self._finish(memory, Status.failed, Reason.perception,
                                "a leg ended but perception cannot be asked to look again "
                                "(perception_status is not connected)")
        status: PerceptionStatus = self._perception_port.Eval(context)
        if status.request != memory.looks:
            if context.get_time() >= memory.t_leg + self._config.planning_timeout:
                return self._finish(memory, Status.failed, Reason.timeout,
                                    f"perception did not look again within planning_timeout = "
                                    f"{self._config.planning_timeout} s")
            return memory
        if not status.ok:
            return self._finish(memory, Status.failed, Reason.perception,
                                f"looking again after a place-and-regrasp leg: {status.error}")
        return dataclasses.replace(memory, phase=Phase.gate, t_leg=context.get_time())

    def _task_check(self, X_WO: RigidTransform, plan, contacts, *, released: bool, poses=(),
                    held_at_pour: bool = False) -> TaskOutcome | None:
        """The given task's judgement at the end of the plan (None when no task is given)."""
        task, model = self._task, self._model
        if not task:
            return None
        if task in REST_POSE_OF_TASK:
            on_support = touches_table(contacts, geometries=model.geometries)
            return judge_rest_pose(task, X_WO.GetAsMatrix4(), np.array(model.X_WT),
                                   is_tool=model.is_tool, p_WC=X_WO.multiply(np.array(model.p_OC)),
                                   target_xy=plan.X_WO_place[:2, 3],
                                   released=released and on_support)
        if task == "p&pOn":
            surfaces = dict(model.surfaces)
            if self._place_on not in surfaces:
                return TaskOutcome(task, False, {}, "the scenario has no surface to place on")
            table_top = model.geometries.table - frozenset().union(*surfaces.values())
            on = {name: _touches(contacts, model.geometries.object, ids)
                  for name, ids in (("surface", surfaces[self._place_on]), ("table", table_top))}
            return judge_on_surface(self._place_on, on_surface=on["surface"],
                                    on_table=on["table"], released=released)
        if task in ("pourOut", "pourIn"):
            poured = plan.t_pour is not None
            if self._count_contents is None:
                what = ("tilted over the bowl" if poured else
                        "placed as for pick-and-place (no bowl: task.pour_into)")
                return TaskOutcome(task, False, {"poured": poured},
                                   f"{what}; the station has no contents to count "
                                   "(`contents: {model: spheres}`)")
            counts = self._count_contents(poses)
            into = self._pour_into if task == "pourOut" else self._container
            return judge_pour(task, counts, into=into, held=held_at_pour)
        if task == "pass":
            return TaskOutcome(task, False, {"handed_over": False},
                               "the station has no receiver: placed as for pick-and-place")
        return TaskOutcome(task, False, {}, f"the {task} motion and check are not implemented "
                           "yet: the object was placed as for pick-and-place")

    def _judge_pass(self, context, memory: _Memory, contacts, hand, poses) -> TaskOutcome:
        """pass at the end of the plan: the receiver's hold since the robot's release."""
        receiver = self._model.receiver
        if receiver is None or not self._receiver_port.HasValue(context):
            return TaskOutcome("pass", False, {}, "the station has no receiver")
        got = hand_contact(contacts, wsg_q=self._receiver_port.Eval(context)[:2],
                           geometries=receiver,
                           R_WG=poses[receiver.gripper].rotation())
        X_WO = poses[self._model.object_body]
        z = memory.z_released + (float(X_WO.multiply(np.array(self._model.p_OC))[2]),)
        received = part_touched(
            contact_points(contacts_of(contacts), a=receiver.left | receiver.right,
                           b=receiver.object),
            X_WO.GetAsMatrix4(), *(self._model.part_vertices or (None, None)))
        return judge_pass(receiver=got, robot_touches=hand.left or hand.right,
                          received_part="" if received is None else PART_LABELS[received],
                          on_table=touches_table(contacts, geometries=self._model.geometries),
                          z_W=np.array(z), held_for=context.get_time() - memory.t_released,
                          hold_duration=memory.status.plan.handover.hold_duration,
                          receiver_part=memory.status.plan.handover.part)

    # Outputs.
    def _memory_of(self, context) -> _Memory:
        return context.get_abstract_state(self._memory).get_value()

    def _calc_collisions(self, context, output):
        output.set_value(self._memory_of(context).collisions)

    def _calc_no_hold(self, context, output):
        output.set_value(self._memory_of(context).no_hold)

    def _calc_request(self, context, output):
        memory = self._memory_of(context)
        output.set_value(PlanRequest(attempt=memory.attempt,
                                     exclude_parts=memory.collisions + memory.no_hold,
                                     regrasp=(self._task in REST_POSE_OF_TASK and len(
                                         memory.legs) - memory.retries
                                         < self._config.max_regrasps),
                                     return_home=memory.retries < self._config.max_retries,
                                     reseats=memory.reseats))

    def _calc_dispenser(self, context, output):
        """1 while a pourIn plan holds the container under the dispenser (its first
        `dispense_duration` seconds), else 0."""
        memory = self._memory_of(context)
        plan = memory.status.plan if memory.status is not None else None
        open_ = False
        if self._task == "pourIn" and plan is not None and plan.t_pour is not None:
            t = context.get_time() - memory.status.t_plan
            open_ = plan.t_pour[0] <= t < plan.t_pour[0] + self._dispense_duration
        output.SetAtIndex(0, 1.0 if open_ else 0.0)

    def _calc_outcome(self, context, output):
        memory = self._memory_of(context)
        if memory.outcome is not None:
            output.set_value(memory.outcome)
            return
        waiting = {Phase.gate: "waiting for the gate check",
                   Phase.planning: f"waiting for plan attempt {memory.attempt}",
                   Phase.executing: f"executing the plan (checks passed: {memory.checks_passed})",
                   Phase.looking: f"waiting for perception to look again (request "
                                  f"{memory.looks + (memory.look_after is not None)}, after "
                                  f"leg {len(memory.legs)})"}
        # A run stopped now (a timeout, an error) has not done its task.
        task = (TaskOutcome(self._task, False, {}, f"not done: {waiting[memory.phase]}")
                if self._task else None)
        output.set_value(Outcome(Status.pending, Reason.none, waiting[memory.phase],
                                 unreachable_parts=memory.collisions,
                                 requeries=memory.requeries, task_outcome=task,
                                 legs=memory.legs))


def _touches(contact_results, a: frozenset, b: frozenset) -> bool:
    """Does any geometry of `a` touch one of `b` (a hydroelastic surface or a point pair)?"""
    return any((x in a and y in b) or (y in a and x in b)
               for x, y in contact_pairs(contact_results))


def _why(failures: tuple) -> str:
    """The last failure's reason, with the first one's when they differ (the first is usually the
    informative one: later attempts only find nothing left to try)."""
    last = failures[-1][1]
    first_part, first = failures[0]
    if len(failures) == 1 or first == last:
        return last
    return f"{last} (first failure, {first_part or 'no part'}: {first})"
