"""The grasp planner: from ranked grasp candidates to a pick-and-place joint trajectory.

    result = plan_pick_and_place(candidates, target=obj, obstacles=others, place_xy=(0.75, -0.3),
                                 q_start=q)
    if result.status == "planned":
        result.plan.q(t), result.plan.v(t), result.plan.width(t)

Candidates are tried best first (paper section VI: the pre-grasp hypotheses are pruned "by a
collision checker and the motion trajectory planner"), each pose as given: the feasibility stage
(tg_drake.grasping.feasibility) has judged every pose — collisions, P(hold) and the geometric
refusals of `tg_drake.grasping.pads` — and a pose it ruled out has score 0 and is not tried. The
planner accepts or refuses grasps by reach alone. For a candidate grasp pose X_WG
(gripper frame G: fingers close along ±x_G, approach along +y_G) the planner needs
inverse-kinematics solutions, inside the joint limits and clear of collisions, for

    pre-grasp   X_WG moved `pregrasp_distance` back along −y_G     (the target is an obstacle)
    grasp       X_WG                                                (the target is not)
    lift        X_WG raised `lift_height`                           (the target is in the hand)
    pre-place   the place pose raised `lift_height`                 (in the hand)
    place       X_WG carried with the object to X_WO_place          (in the hand)
    retreat     the place pose moved `retreat_distance` along −y_G  (the target at the place)

where X_WO_place is the object's pose X_WO moved to the place target's xy, its orientation kept
(or turned about the vertical by one of `place_yaws` when the kept one cannot be placed), and
raised so that the lowest corner of the box it carries (`carried_box`: its perceived points'
box with one side vertical) is `release_height` above the table. The IK is local,
so every pose is tried from several seeds (the start posture, IIWA_HOME and postures turned
towards the target). The joint trajectories between these configurations come from
`tg_drake.planning.trajectory.plan_segment` (kinematic trajectory optimisation, collision checked
densely); approach, lift, descent and retreat are straight-line moves of the gripper.

The first candidate for which everything succeeds is chosen. A failure is a result, not an
exception: `PlanResult(status="unreachable", unreachable_parts=..., reason=...)`, and every
candidate found infeasible gets cost inf. A candidate fails on the pick side (its pre-grasp,
grasp or lift pose, or the motions to and through them) or on the place side (pre-place, place,
retreat). The parts none of whose candidates can even be picked are `unreachable_parts`: what the
logic receives as `collision(Part)` evidence (`tg_drake.systems.grasp_planner`). A part that can
be picked but not placed is not a collision of that part: the place target is the problem, and
the result says so. A pass is the exception: the hand-over point is fixed, and whether the arm
reaches it and the receiver finds a part free depends on the grasp alone, so there a part none of
whose candidates can be picked and handed over is an unreachable part.

Obstacles are the perceived objects' bounding boxes (`ObjectDescription.X_WO`, `extents`); the
held object is its bounding box welded to the gripper.
"""


import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np
from pydrake.math import RigidTransform
from pydrake.trajectories import BsplineTrajectory, CompositeTrajectory, PiecewisePolynomial

from tg_drake.errors import ScenarioError
from tg_drake.logic.receive import receiver_parts
from tg_drake.perception.geometry import inverse, make_transform
from tg_drake.planning.handover import (
    Handover,
    choose_receiver_grasp,
    handover_object_poses,
    receiver_motion,
)
from tg_drake.planning.ik import (
    ArmPlant,
    arm_surface_points,
    budget_spent,
    make_arm_plant,
    solve_ik_seeds,
)
from tg_drake.planning.task_motion import (
    TaskPlacing,
    bowl_of,
    box_top,
    fill_poses,
    pour_poses,
    turned_retreat,
)
from tg_drake.planning.trajectory import (
    SegmentConfig,
    SegmentLimits,
    StraightLine,
    plan_segment,
    shifted,
)
from tg_drake.robot import (
    IIWA_HOME,
    WSG_MAX_OPENING,
)
from tg_drake.types import PART_LABELS, GraspCandidates, ObjectDescription, SceneDescription

# A plan request's budget of inverse-kinematics solver calls (PlannerConfig.max_ik_solves): a
# compute bound, not a fitted number. A request that plans explores a few hundred to a few thousand
# (tens of seconds on a 2-core machine); one that fails can otherwise explore every candidate,
# place yaw and intermediate pose of a place-and-regrasp (tens of thousands: ten minutes).
MAX_IK_SOLVES = 6000


@dataclass
class PlannerConfig:
    """Distances, clearances, gripper timing and limits of the pick-and-place plan."""

    pregrasp_distance: float = 0.10  # [m] the pre-grasp stands this far back along −y_G.
    lift_height: float = 0.15  # [m] lift (and pre-place height above the place pose).
    retreat_distance: float = 0.10  # [m] after release, back along −y_G.
    release_height: float = 0.01  # [m] gap under the object's box at the place pose.
    open_width: float = WSG_MAX_OPENING  # [m] WSG opening while moving (its full stroke).
    closed_width: float = -0.04  # [m] commanded to grasp, past closed: each finger's P term
    # (kp 2000 N/m × (w/2 + 20 mm) on an object w wide) grips with 40 N + 1000 N/m · w, up to the
    # WSG driver's force limit (80 N from w = 40 mm).
    squeeze_duration: float = 0.1  # [s] 0 → closed_width, after the fingers have closed
    # slowly (open → 0 over close_duration) so that they meet a light object gently; and back
    # closed_width → 0 at release, before opening over open_duration.
    close_duration: float = 0.8  # [s] opening → closed command ramp (scripted.py's timing).
    settle_duration: float = 0.4  # [s] hold after closing, before lifting.
    open_duration: float = 0.5  # [s] closed → open at release.
    release_dwell: float = 0.15  # [s] the pads held open at the place before the retreat: the
    # supervisor looks there whether the object came free of them, and may have the plan
    # re-seat it (`reseated`; SupervisorConfig.max_reseats) before the retreat begins.
    min_distance: float = 0.01  # [m] clearance of free and carrying motions.
    contact_min_distance: float = 0.003  # [m] clearance near the target (approach, grasp,
    # lift, descent, place, retreat), where the fingers straddle the object.
    ik_position_tolerance: float = 0.002  # [m] per axis.
    ik_angle_tolerance: float = 0.02  # [rad]
    seed_postures: list[list[float]] = field(default_factory=lambda: [
        list(IIWA_HOME),
        [0.0, 0.6, 0.0, -1.3, 0.0, 1.0, 0.0],  # reaching forward and low
        [0.0, 0.3, 0.0, -1.6, 0.0, -1.0, 0.0],  # wrist flipped
        [0.0, 0.2, 0.0, -1.0, 0.0, 1.6, 0.0],  # from above
    ])  # [rad] IK seeds; each is also tried with joint 1 turned towards the target.
    place_yaws: list[float] = field(  # [deg] turns of the object
        default_factory=lambda: [0.0, 60.0, -60.0, 120.0, -120.0, 180.0])
    # about the vertical tried at the place, in order (the first one that can be planned).
    max_ik_solves: int | None = MAX_IK_SOLVES  # a plan request's budget of inverse-kinematics
    # solver calls, its place-and-regrasp search included (None: no budget): where it runs out,
    # the request ends without a plan and says so (`budget_reason`)
    max_candidates_per_part: int = 12  # scored hypotheses per part (each with its approach
    # variants, `GraspCandidates.source`) that reach the inverse kinematics before the part is
    # given up.
    free_limits: SegmentLimits = field(default_factory=SegmentLimits)  # moving to the pre-grasp
    contact_limits: SegmentLimits = field(default_factory=lambda: SegmentLimits(
        velocity_scale=0.25, min_duration=1.0))  # straight moves at the object
    carry_limits: SegmentLimits = field(default_factory=lambda: SegmentLimits(
        velocity_scale=0.5, min_duration=1.0))  # carrying the object to the pre-place
    segment: SegmentConfig = field(default_factory=SegmentConfig)

    def validate(self, where: str = "pipeline.planner") -> None:
        """Raises ScenarioError naming the field a value is out of its range in."""
        if self.max_ik_solves is not None and self.max_ik_solves < 1:
            raise ScenarioError(f"must be >= 1 or null (no budget), got {self.max_ik_solves}",
                                field=f"{where}.max_ik_solves")
        if self.max_candidates_per_part < 1:
            raise ScenarioError(f"must be >= 1, got {self.max_candidates_per_part}",
                                field=f"{where}.max_candidates_per_part")


def budget_reason(config: PlannerConfig) -> str:
    """What a plan request that ran out of its budget says."""
    return (f"the planning budget of {config.max_ik_solves} inverse-kinematics solves ran out "
            f"(pipeline.planner.max_ik_solves)")


@dataclass(frozen=True)
class Plan:
    """A pick-and-place plan; its time starts at 0 (the system offsets it by the planning time)."""

    q_traj: CompositeTrajectory  # (7,) iiwa joint positions [rad]
    v_traj: object  # (7,) its time derivative [rad/s]
    width_traj: PiecewisePolynomial  # (1,) commanded WSG opening [m]
    t_grasp_closed: float  # [s] the closing command has reached `closed_width` and settled
    t_lift_done: float  # [s]
    t_place_done: float  # [s] the object is released at the place pose
    duration: float  # [s] end of the retreat
    candidate: int  # index into the GraspCandidates
    part: str  # its part name
    X_WG_grasp: np.ndarray  # 4×4 grasp pose
    X_WO_place: np.ndarray  # 4×4 object pose at release
    waypoints: dict  # name → (7,) iiwa configuration
    segments: tuple  # (name, t_start, t_end, min_clearance [m]) per moving segment
    R_turn: np.ndarray | None = None  # 3×3 world-frame rotation the plan gives the object
    # beyond a turn about the vertical (a task's resting pose); None: its orientation is kept
    t_pour: tuple | None = None  # [s] (start, end) of holding the container tilted over the
    # bowl (pourOut) or under the dispenser (pourIn); None when the plan pours nothing
    t_handover: tuple | None = None  # [s] (receiver closes, robot released) of a pass; None:
    # no hand-over
    handover: object | None = None  # pass: the receiver's motion (planning.handover.
    # HandoverMotion, its grasp and part), in plan time; None: no hand-over
    t_descend: float | None = None  # [s] the descent to the place pose begins (the carry and
    # any pour are over); None: not recorded
    t_opened: float | None = None  # [s] the pads are commanded fully open at the place; the arm
    # holds still until `t_place_done` (PlannerConfig.release_dwell); None: no such pause (a pass)
    regrasp: bool = False  # the plan ends with the object placed in an intermediate resting pose
    # and the arm back at its start (out of the camera's view): a place-and-regrasp's first leg
    # (tg_drake.planning.regrasp); the supervisor looks again and plans the next leg

    def pads_open_at_place(self, t: float) -> bool:
        """Whether at plan time t the pads stand open at the place before the retreat (where a
        re-seat can be inserted: `reseated`)."""
        return self.t_opened is not None and self.t_opened <= t < self.t_place_done

    def q(self, t: float) -> np.ndarray:
        """(7,) joint positions at plan time t (held at the ends outside [0, duration])."""
        t = min(max(t, 0.0), self.duration)
        return self.q_traj.value(t)[:, 0]

    def v(self, t: float) -> np.ndarray:
        """(7,) joint velocities at plan time t (zero outside [0, duration])."""
        if t < 0.0 or t > self.duration:
            return np.zeros(7)
        return self.v_traj.value(t)[:, 0]

    def width(self, t: float) -> float:
        """Commanded WSG opening [m] at plan time t."""
        t = min(max(t, 0.0), self.duration)
        return float(self.width_traj.value(t)[0, 0])


@dataclass(frozen=True)
class PlanResult:
    """What `plan_pick_and_place` found: a plan, or why there is none."""

    status: str  # "planned" or "unreachable"
    plan: Plan | None
    costs: np.ndarray  # (M,) per candidate: −log(score) if chosen, inf if infeasible, nan if
    # not examined (a better candidate was chosen first, or its part was not tried).
    candidate_reasons: tuple  # (M,) why each infeasible candidate failed ("" otherwise)
    part_reachable: dict  # examined part name → whether any of its pre-grasps had an IK solution
    unreachable_parts: tuple  # examined parts none of whose candidates can be picked
    reason: str = ""
    planning_time: float = 0.0  # [s] wall time
    candidate: int | None = None
    part: str | None = None
    picked_parts: tuple = ()  # examined parts some candidate of which can be picked (when no
    # plan: picked, but not placed, poured or handed over)
    ik_solves: int = 0  # inverse-kinematics solver calls of the request (`plan_task_leg`)
    out_of_budget: bool = False  # the request's budget (PlannerConfig.max_ik_solves) ran out
    # before a plan was found (`plan_task_leg`)


def _closing(t0: float, c: PlannerConfig) -> list[tuple[float, float]]:
    """(time [s], commanded opening [m]) knots of a grasp's close from `t0`: open → 0 over
    `close_duration` (meeting a light object gently), then the squeeze to `closed_width`."""
    return [(t0, c.open_width), (t0 + c.close_duration, 0.0),
            (t0 + c.close_duration + c.squeeze_duration, c.closed_width)]


def _releasing(t0: float, c: PlannerConfig) -> list[tuple[float, float]]:
    """The knots of a release from `t0`: the squeeze back to 0, then open."""
    return [(t0, c.closed_width), (t0 + c.squeeze_duration, 0.0),
            (t0 + c.squeeze_duration + c.open_duration, c.open_width)]


def reseat_duration(config: PlannerConfig) -> float:
    """[s] A re-seat: the pads close on the object where it stands, squeeze, settle, let go and
    open again (the grasp's own timing: `_closing`, `settle_duration`, `_releasing`)."""
    return (config.close_duration + 2 * config.squeeze_duration + config.settle_duration
            + config.open_duration)


def reseated(plan: Plan, t_at: float, config: PlannerConfig) -> Plan:
    """`plan` with a re-seat inserted at plan time `t_at`, while the pads stand open at the
    place (`plan.t_opened` ≤ t_at < `plan.t_place_done`): the arm holds its place posture while
    the pads close on the object where it now stands and open again, holds
    `config.release_dwell` more, then retreats as planned. An object that settled against one
    pad as the pads opened (a lying cup rolling onto the pad whose tip is under its rim) is
    pushed back between them, and let go from rest. Everything after the place is delayed."""
    if not plan.pads_open_at_place(t_at):
        raise ValueError(f"a re-seat needs the pads open at the place: t_at = {t_at} s outside "
                         f"[{plan.t_opened}, {plan.t_place_done}) s")
    t_opened = t_at + reseat_duration(config)
    t_done = t_opened + config.release_dwell
    shift = t_done - plan.t_place_done
    q_place = plan.q(t_at)
    pieces = []
    for k in range(plan.q_traj.get_number_of_segments()):
        piece = plan.q_traj.segment(k)
        start, end = piece.start_time(), piece.end_time()
        if end <= t_at + 1e-9:
            pieces.append(piece)
        elif start <= t_at:  # the hold at the place, stretched to the new end of the pause
            pieces.append(PiecewisePolynomial.ZeroOrderHold(
                [start, end + shift], np.column_stack([q_place, q_place])))
        else:
            pieces.append(_delayed(piece, shift))
    q_traj = CompositeTrajectory(pieces)
    before = [(t, plan.width(t)) for t in plan.width_traj.get_segment_times() if t < t_at]
    released = t_opened - config.squeeze_duration - config.open_duration
    later = [(t + shift, plan.width(t)) for t in plan.width_traj.get_segment_times()
             if t > plan.t_place_done] or [(plan.duration + shift, plan.width(plan.duration))]
    knots = before + _closing(t_at, config) + _releasing(released, config) + later
    width_traj = PiecewisePolynomial.FirstOrderHold([t for t, _ in knots],
                                                    np.array([[w for _, w in knots]]))
    segments = tuple((name, a + shift, b + shift, clearance) if a >= plan.t_place_done
                     else (name, a, b, clearance) for name, a, b, clearance in plan.segments)
    return dataclasses.replace(plan, q_traj=q_traj, v_traj=q_traj.MakeDerivative(),
                               width_traj=width_traj, t_opened=t_opened, t_place_done=t_done,
                               duration=plan.duration + shift, segments=segments)


def _delayed(piece, shift: float):
    """One piece of a plan's joint trajectory, `shift` seconds later."""
    if isinstance(piece, BsplineTrajectory):
        return shifted(piece, piece.start_time() + shift)
    moved = PiecewisePolynomial(piece)
    moved.shiftRight(shift)
    return moved


def place_pose(X_WO: np.ndarray, extents, place_xy, *, table_z: float = 0.0,
               release_height: float = 0.01, X_OB=None) -> np.ndarray:
    """X_WO moved to `place_xy` (world) with its orientation kept, its box's lowest corner
    `release_height` above the table top at `table_z`. The box: sides `extents` [m], at X_OB
    (4×4) in the object frame (None: centred on O, along its axes — the perceived box)."""
    corners = np.array(np.meshgrid(*[(-0.5, 0.5)] * 3)).reshape(3, -1).T * np.asarray(extents)
    if X_OB is not None:
        X_OB = np.asarray(X_OB, float)
        corners = corners @ X_OB[:3, :3].T + X_OB[:3, 3]
    lowest = np.min((X_WO[:3, :3] @ corners.T)[2])  # relative to the origin of O
    X = X_WO.copy()
    X[:2, 3] = place_xy
    X[2, 3] = table_z + release_height - lowest
    return X


@dataclass(frozen=True)
class CarriedBox:
    """The box the planner carries in the hand and sets down for a target: its perceived points'
    box with one side vertical as the object rests now (the other two along the points'
    principal horizontal directions), in the object frame O. Kept level, it sets the object
    down at the height its points rest at now: the perceived box (`ObjectDescription.extents`)
    follows the object's axes, and of a lying object turned about its axis (a mug whose handle
    points up at a slant) its lowest corner lies centimetres under the points, which put the
    object down that much too high, to drop and roll."""

    X_OB: np.ndarray  # 4×4 pose of the box's centre and axes in O
    size: tuple[float, float, float]  # [m] its sides


def carried_box(target: ObjectDescription) -> CarriedBox:
    """The `CarriedBox` of a perceived object (the perceived box itself when it has fewer than
    four points)."""
    p = np.asarray(target.p_W, float).reshape(-1, 3)
    X_WO = np.asarray(target.X_WO, float)
    if len(p) < 4:
        return CarriedBox(np.eye(4), tuple(float(e) for e in target.extents))
    xy = p[:, :2] - p[:, :2].mean(axis=0)
    _, vecs = np.linalg.eigh(xy.T @ xy)
    x = np.append(vecs[:, 1], 0.0)
    R_WB = np.column_stack([x, np.cross([0.0, 0.0, 1.0], x), [0.0, 0.0, 1.0]])
    q = p @ R_WB
    lo, hi = q.min(axis=0), q.max(axis=0)
    X_WB = make_transform(R_WB, R_WB @ (0.5 * (lo + hi)))
    return CarriedBox(inverse(X_WO) @ X_WB, tuple(float(v) for v in hi - lo))


def plan_for_scene(scene: SceneDescription, candidates: GraspCandidates, *, place_xy, q_start,
                   **kwargs) -> PlanResult:
    """`plan_pick_and_place` with the target `candidates.target` of `scene`, the other objects as
    obstacles and the table height from the scene's table frame."""
    target = scene.objects[candidates.target]
    others = [o for i, o in enumerate(scene.objects) if i != candidates.target]
    return plan_pick_and_place(candidates, target=target, obstacles=others, place_xy=place_xy,
                               q_start=q_start, table_z=float(scene.X_WT[2, 3]), **kwargs)


def plan_pick_and_place(candidates: GraspCandidates, *, target: ObjectDescription,
                        obstacles=(), place_xy, q_start=IIWA_HOME, table_z: float = 0.0,
                        config: PlannerConfig | None = None, scenario=None,
                        exclude_parts=(), max_parts: int | None = None,
                        placing: TaskPlacing | None = None, surfaces=(),
                        handover: Handover | None = None,
                        category: dict | None = None) -> PlanResult:
    """The first candidate (by score) with a full collision-free pick-and-place plan.

    Args:
        candidates: grasp poses X_WG with part labels and scores.
        target: the object to pick; obstacles: the other objects (their boxes are obstacles).
        place_xy: (2,) world xy where the object's frame origin goes.
        q_start: (7,) iiwa configuration the plan starts from.
        table_z: world height of the table top.
        scenario: its directives give the robot and table models (default: the station's).
        exclude_parts: part names not to try (already found unreachable).
        max_parts: try only the candidates of the first this many parts (in order of their best
            candidate); None tries all.
        placing: the task's placing (`tg_drake.planning.task_motion.task_placing`: a resting
            pose to turn the object into, a surface to put it on); None places it at `place_xy`
            on the table, its orientation kept.
        surfaces: `Surface` boxes standing on the table, obstacles of every motion.
        handover: a pass (tg_drake.planning.handover): the object goes to the hand-over point
            in the air (its orientation kept, turned about the vertical by `place_yaws`), the
            receiver takes it by the part the logic names for it (`category`: the logic's
            category distribution), then the robot opens and retreats.
    """
    config = config or PlannerConfig()
    t_start = time.perf_counter()
    q_start = np.asarray(q_start, float)
    m = len(candidates.score)
    costs = np.full(m, np.nan)
    reasons = [""] * m
    part_reachable: dict[str, bool] = {}
    part_pickable: dict[str, bool] = {}

    # Candidates in order of score, grouped into the parts to try. A score of 0 means the logic,
    # the grasp model or the feasibility stage ruled the candidate out: it is infeasible, but says
    # nothing about reach.
    score = np.asarray(candidates.score, float)
    viable = np.isfinite(score) & (score > 0.0)
    costs[~viable] = np.inf
    given = tuple(candidates.feasibility_reasons)
    for i in np.flatnonzero(~viable):
        reasons[i] = ((given[i] if len(given) == m and given[i] else "")
                      or "score 0: ruled out by the logic, the grasp model or feasibility")
    order = [i for i in np.argsort(-score, kind="stable") if viable[i]]
    parts_order = []
    for i in order:
        name = PART_LABELS[int(candidates.parts[i])]
        if name not in exclude_parts and name not in parts_order:
            parts_order.append(name)
    if max_parts is not None:
        parts_order = parts_order[:max_parts]
    if not parts_order:
        return PlanResult("unreachable", None, costs, tuple(reasons), {}, (),
                          "no candidate grasps left to try", time.perf_counter() - t_start)
    # The scored hypothesis each pose was made from (its approach variants share it).
    source = (np.arange(m) if candidates.source is None
              else np.asarray(candidates.source, int))

    X_WO = np.asarray(target.X_WO, float)
    held = carried_box(target)
    X_WO_place = place_pose(X_WO, held.size, place_xy, table_z=table_z,
                            release_height=config.release_height, X_OB=held.X_OB)
    if placing is not None:
        place_xy = placing.place_xy
        X_WO_place = place_pose(X_WO, held.size, place_xy, table_z=placing.support_z,
                                release_height=config.release_height, X_OB=held.X_OB)
    boxes = [(f"object{i}", RigidTransform(o.X_WO), tuple(o.extents))
             for i, o in enumerate(obstacles)]
    boxes += [(f"surface_{s.name}", RigidTransform(np.asarray(s.X_WB)), tuple(s.size))
              for s in surfaces]
    arms = _Arms(scenario, config.open_width, boxes, target_shapes(target), held.size,
                 X_WO=X_WO, X_OB=held.X_OB)
    bearing = float(np.arctan2(X_WO[1, 3], X_WO[0, 3]))
    seeds = _seeds(q_start, config.seed_postures, bearing)

    receiver_cache: dict = {}  # a pass: the receiver's feasibility per robot grasp
    tried: dict[str, set] = {name: set() for name in parts_order}
    plan = None
    for i in order:
        if budget_spent():  # (plan_task_leg's reason says so)
            break
        part = PART_LABELS[int(candidates.parts[i])]
        if part not in tried or (source[i] not in tried[part]
                                 and len(tried[part]) >= config.max_candidates_per_part):
            continue
        tried[part].add(int(source[i]))
        part_reachable.setdefault(part, False)
        part_pickable.setdefault(part, False)
        X_WG = np.asarray(candidates.X_WG[i], float)
        found = False
        places = _task_place_variants(X_WO_place, config, placing=placing, X_WO=X_WO,
                                      X_WG=X_WG, extents=held.size, is_tool=target.is_tool,
                                      X_OB=held.X_OB)
        if handover is not None:  # a pass: handed over in the air (planning.handover), where
            # the arm can reach with this grasp
            places = [(None, X) for X in handover_object_poses(
                handover, X_WO, X_WG, yaws_deg=config.place_yaws, lift=config.lift_height,
                retreat=config.retreat_distance)]
            if not places:
                costs[i] = np.inf
                reasons[i] = _farthest(reasons[i], "pre-place pose: the hand-over points are out "
                                       "of the arm's reach with this grasp (its wrist outside "
                                       "the shell joint 4 allows)")
                continue
        if not places:
            # A tool rests only flat; any other object's turns were refused because its fingers
            # would carry it at the release: a place-and-regrasp may do (TURNED_IN_HAND).
            why = ("" if target.is_tool else
                   f" with the fingers letting go, {TURNED_IN_HAND} {placing.pose} in the hand")
            costs[i] = np.inf
            reasons[i] = _farthest(reasons[i], f"place pose: {target_name(target)} cannot "
                                   f"be turned to rest {placing.pose}{why}")
            continue
        pours, why = _pours(placing, obstacles, target, X_WG)
        if not pours:
            costs[i], reasons[i] = np.inf, _farthest(reasons[i], why)
            continue
        failed_pours = set()
        for k_pour, pour, R_turn, X_WO_place_yawed in [
                (k, pour, R, X) for k, pour in enumerate(pours) for R, X in places]:
            if budget_spent():
                break
            if k_pour in failed_pours:
                continue
            key = _key_poses(arms, X_WG, X_WO, X_WO_place_yawed, config, R_turn=R_turn,
                             pour=pour, pour_hold=placing.hold if pour else 0.0)
            below = [n for n in ("pre-grasp", "grasp") if key.X[n].translation()[2] < table_z]
            if below:  # the WSG body's origin under the table top: no need to ask the IK
                costs[i] = np.inf
                reasons[i] = _farthest(reasons[i],
                                       f"{below[0]} pose puts the gripper under the table")
                break
            poses, failure = _waypoint_configurations(arms, key, seeds, config)
            if "pre-grasp" in poses:
                part_reachable[part] = True
            if failure and R_turn is not None and failure.startswith(PLACE_FAILURES):
                failure += f", {TURNED_IN_HAND} {placing.pose} in the hand"
            if failure.startswith(POUR_FAILURES):  # another pour may do
                failed_pours.add(k_pour)
            if failure:
                # Failing on a place pose, the pick poses were reachable (motions untried): the
                # object turned another way at the place may do.
                picked = PICK_POSES <= set(poses)
                part_pickable[part] |= picked
                costs[i], reasons[i] = np.inf, _farthest(reasons[i], failure)
                if picked:
                    continue
                break
            receiving = None
            if handover is not None:  # the receiver clear of the arm as it stands there
                receiving, why = _receiving(handover, candidates, target, part, X_WO,
                                            X_WO_place_yawed, key, config, table_z, category,
                                            receiver_cache,
                                            arm_p_W=arm_surface_points(arms.free, poses["place"]))
                if receiving is None:  # picked, not handed over: another place yaw may do
                    part_pickable[part] |= PICK_POSES <= set(poses)
                    costs[i], reasons[i] = np.inf, _farthest(reasons[i], why)
                    continue
            plan, failure, picked = _trajectories(arms, q_start, poses, key, config, seeds,
                                                  candidate=int(i), part=part,
                                                  receiving=receiving)
            part_pickable[part] |= picked
            if plan is None and R_turn is not None and failure.startswith(PLACE_FAILURES):
                failure += f", {TURNED_IN_HAND} {placing.pose} in the hand"
            if plan is None:
                if failure.startswith(POUR_FAILURES):
                    failed_pours.add(k_pour)
                costs[i], reasons[i] = np.inf, _farthest(reasons[i], failure)
                if picked:
                    continue
                break
            costs[i] = -np.log(score[i])
            found = True
            break
        if found or budget_spent():
            break

    elapsed = time.perf_counter() - t_start
    unreachable = tuple(p for p in parts_order if p in part_pickable and not part_pickable[p])
    if plan is None and handover is not None and not budget_spent():
        # A pass: where the object is handed over and whether the receiver finds a part free
        # depend on the grasp alone (the hand-over point is fixed), so a part none of whose
        # candidates both picks and hands over is blamed like one that cannot be picked.
        unreachable = tuple(p for p in parts_order if p in part_pickable)
    if plan is None:
        examined = [r for r in reasons if r]
        first = examined[0] if examined else "none examined"
        if unreachable and handover is not None:
            reason = (f"no candidate of {', '.join(unreachable)} can be picked and handed "
                      "over; farthest: " + max(examined or [first], key=_stage))
        elif unreachable:
            reason = (f"no candidate of {', '.join(unreachable)} can be picked; first failure: "
                      + first)
        else:
            reason = ("the object can be picked but not placed at "
                      f"({place_xy[0]:.3f}, {place_xy[1]:.3f}) m: "
                      + max(examined or [first], key=_stage))  # the first farthest
        picked = tuple(p for p in parts_order if part_pickable.get(p))
        return PlanResult("unreachable", None, costs, tuple(reasons), part_reachable,
                          unreachable, reason, elapsed, picked_parts=picked)
    return PlanResult("planned", plan, costs, tuple(reasons), part_reachable, unreachable, "",
                      elapsed, plan.candidate, plan.part)


def _farthest(old: str, new: str) -> str:
    """Of two reasons a candidate's variants failed, the one that got farthest: a pass's receiver
    failure (the robot's every waypoint was found) over a place failure (the pick was found)
    over a pick failure, else the first."""
    if not old or _stage(new) > _stage(old):
        return new
    return old


def _stage(reason: str) -> int:
    return 2 if reason.startswith(RECEIVER_FAILURE) else 1 if reason.startswith(PLACE_FAILURES) \
        else 0


def _place_variants(X_WO_place: np.ndarray, config: PlannerConfig) -> list[np.ndarray]:
    """The place pose turned about the vertical through the object's centre by each of
    `config.place_yaws`: the task says where the object goes, not which way it faces."""
    out = []
    for yaw in np.deg2rad(config.place_yaws):
        c, s_ = np.cos(yaw), np.sin(yaw)
        X = X_WO_place.copy()
        X[:3, :3] = np.array([[c, -s_, 0.0], [s_, c, 0.0], [0.0, 0.0, 1.0]]) @ X_WO_place[:3, :3]
        out.append(X)
    return out


def _task_place_variants(X_WO_place: np.ndarray, config: PlannerConfig, *,
                         placing: TaskPlacing | None, X_WO: np.ndarray, X_WG: np.ndarray,
                         extents, is_tool: bool = False, X_OB=None) -> list[tuple]:
    """(R_turn, X_WO_place) to try for grasp X_WG: the task's place poses (`placing`), each
    turned about the vertical by `config.place_yaws` (`_place_variants`). R_turn is the world
    rotation the plan gives the object when it turns it into another resting pose (the yaw
    included), None when its orientation is kept. `extents`, `X_OB`: the box set down
    (`place_pose`)."""
    if placing is None:
        return [(None, X) for X in _place_variants(X_WO_place, config)]
    out = []
    for R_turn, X_place in placing.place_poses(X_WO, X_WG, extents, is_tool=is_tool,
                                               release_height=config.release_height,
                                               place_pose=place_pose, X_OB=X_OB):
        for X in _place_variants(X_place, config):
            turn = None if R_turn is None else X[:3, :3] @ np.asarray(X_WO)[:3, :3].T
            out.append((turn, X))
    return out


def _pours(placing: TaskPlacing | None, obstacles, target: ObjectDescription,
           X_WG: np.ndarray) -> tuple[list, str]:
    """The pours to try for grasp X_WG (`task_motion.pour_poses`: (X_WO_pour, X_WO_tilted)),
    [None] when the task pours nothing; ([], why) when it cannot pour."""
    if placing is not None and placing.fill_at is not None:
        fills = fill_poses(np.asarray(target.X_WO, float), target.extents, gate=placing.fill_at,
                           clearance=placing.fill_clearance, yaws=placing.pour_yaws)
        return (fills, "") if fills else ([], f"pour pose: {target_name(target)} is not upright")
    if placing is None or placing.pour_at is None:
        return [None], ""
    k = bowl_of(obstacles, placing.pour_at)
    if k is None:
        return [], "pour pose: no object perceived to pour into"
    bowl = obstacles[k]
    pours = pour_poses(np.asarray(target.X_WO, float), target.extents, X_WG,
                       bowl_xy=placing.pour_at, bowl_top=box_top(bowl.X_WO, bowl.extents),
                       tilt=placing.pour_tilt, clearance=placing.pour_clearance,
                       drop=placing.pour_drop,
                       yaws=placing.pour_yaws)
    if not pours:
        return [], f"pour pose: {target_name(target)} is not upright"
    return pours, ""


def target_name(target: ObjectDescription) -> str:
    return target.name or "the object"


ROUND_RATIO = 0.85  # a part box whose two cross extents agree this well is taken as round


def target_shapes(target: ObjectDescription) -> list[tuple]:
    """Obstacles standing for the object to be grasped (names target_*): one per part box —
    a cylinder along the object's symmetry axis for a round part of a non-tool (perception's
    completion makes its top, middle and bottom rotationally symmetric), a box otherwise — or the
    whole box when perception gave no part boxes. Round parts as cylinders rather than boxes keep
    the box corners from blocking tilted side grasps that clear the real surface."""
    X_WO = np.asarray(target.X_WO, float)
    if not target.part_boxes:
        return [("target", RigidTransform(X_WO), tuple(target.extents))]
    shapes = []
    z_O = X_WO[:3, 2]
    for name, box in target.part_boxes.items():
        X_WB = np.asarray(box.X_WB, float)
        size = 2.0 * np.asarray(box.half_extents, float)
        along = np.abs(X_WB[:3, :3].T @ z_O)  # which box axis is the symmetry axis
        k = int(np.argmax(along))
        cross = np.delete(size, k)
        if (not target.is_tool and name in ("top", "middle", "bottom") and along[k] > 0.99
                and cross.min() >= ROUND_RATIO * cross.max()):
            X = np.eye(4)
            X[:3, :3] = X_WO[:3, :3]
            X[:3, 3] = X_WB[:3, 3]
            shapes.append((f"target_{name}", RigidTransform(X), (cross.max() / 2, size[k])))
        else:
            shapes.append((f"target_{name}", RigidTransform(X_WB), tuple(size)))
    return shapes


# How a place failure of an object turned into the task's resting pose in the hand ends (the
# place-and-regrasp of tg_drake.planning.regrasp.plan_task_leg looks for it).
TURNED_IN_HAND = "the object turned to rest"

# The key poses and motions of the pick; failures after them are the place's.
PICK_POSES = {"pre-grasp", "grasp", "lift"}
PICK_MOTIONS = ("move", "approach", "lift")
PLACE_FAILURES = ("pre-place pose", "place pose", "retreat pose", "carry trajectory",
                  "descend trajectory", "retreat trajectory", "pour pose", "tilted pose",
                  "tilt trajectory", "untilt trajectory", "return trajectory")  # how their
# reasons start
RECEIVER_FAILURE = "hand-over:"  # how the receiver's reasons start (planning.handover)
POUR_FAILURES = ("pour pose", "tilted pose", "tilt trajectory", "untilt trajectory")


class _Arms:
    """The arm plants of one planning call, each built when first needed.

    free: the other objects and the target are obstacles (moving to the pre-grasp);
    grasp: the same, but the finger pads may overlap the target's box (approach, grasp, lift);
    carry(X_GO): the other objects, and the target's box in the hand (lift to place);
    placed: the other objects and the target's shapes moved with it to its place pose, which the
    finger pads may overlap (release, retreat): the same shapes as at the grasp, so that backing
    out of a placed object is judged as going into it was (the object's whole box there would put
    fingers that straddle a wall or a rim inside it).

    `extents`: the box held in the hand [m], at X_OB in the object frame (None: the perceived
    box, centred on O; `carried_box`); `X_WO`: the target's pose now, where `target_shapes`
    stand."""

    def __init__(self, scenario, opening, boxes, target_shapes, extents, *, X_WO, X_OB=None):
        self._scenario, self._opening = scenario, opening
        self._boxes, self._target = list(boxes), list(target_shapes)
        self._X_OW = RigidTransform(np.asarray(X_WO, float)).inverse()
        self._cache: dict = {}
        self._held_size = tuple(extents)  # the object's box [m], carried in the hand
        self._X_OB = RigidTransform() if X_OB is None else RigidTransform(np.asarray(X_OB, float))

    def _make(self, key, extra=(), held=None, finger_contact=()) -> ArmPlant:
        if key not in self._cache:
            self._cache[key] = make_arm_plant(
                self._scenario, obstacles=self._boxes + list(extra),
                finger_opening=self._opening, held=held, finger_contact=finger_contact)
        return self._cache[key]

    @property
    def free(self) -> ArmPlant:
        return self._make("free", self._target)

    @property
    def grasp(self) -> ArmPlant:
        return self._make("grasp", self._target, finger_contact=[t[0] for t in self._target])

    def placed(self, X_WO_place: np.ndarray) -> ArmPlant:
        key = ("placed", tuple(np.round(np.asarray(X_WO_place).ravel(), 9)))
        shapes = placed_shapes(self._target, self._X_OW, X_WO_place)
        return self._make(key, shapes, finger_contact=[t[0] for t in shapes])

    def carry(self, X_GO: RigidTransform) -> ArmPlant:
        key = ("carry", tuple(np.round(X_GO.GetAsMatrix4().ravel(), 9)))
        return self._make(key, held=(X_GO @ self._X_OB, self._held_size))


def placed_shapes(shapes, X_OW: RigidTransform, X_WO_place) -> list[tuple]:
    """The target's obstacle shapes (`target_shapes`, in the world where the object is now, X_OW
    the inverse of its pose) moved rigidly with the object to `X_WO_place`, renamed
    target_placed_*."""
    X_move = RigidTransform(np.asarray(X_WO_place, float)) @ X_OW
    return [(name.replace("target", "target_placed", 1), X_move @ X, size)
            for name, X, size in shapes]


def _seeds(q_start, postures, bearing) -> list[np.ndarray]:
    seeds = [np.asarray(q_start, float)]
    for posture in postures:
        q = np.asarray(posture, float)
        turned = q.copy()
        turned[0] = bearing
        seeds += [turned, q]
    unique = []
    for q in seeds:
        if not any(np.allclose(q, u) for u in unique):
            unique.append(q)
    return unique


@dataclass
class _KeyPoses:
    """The gripper poses of one candidate and the plant that carries its object."""

    X: dict  # name → RigidTransform X_WG, in execution order
    X_GO: RigidTransform  # the target in the hand
    X_WO_place: np.ndarray  # 4×4 object pose at the place pose
    R_turn: np.ndarray | None = None  # the object's turn into a task's resting pose
    pour_hold: float = 0.0  # [s] held tilted (when X has "pour" and "tilted")


def _key_poses(arms: _Arms, X_WG, X_WO, X_WO_place, config, *, R_turn=None, pour=None,
               pour_hold: float = 0.0) -> _KeyPoses:
    X_WG = RigidTransform(X_WG)
    y_G = X_WG.rotation().col(1)
    up = np.array([0.0, 0.0, config.lift_height])
    X_OG = RigidTransform(X_WO).inverse() @ X_WG
    X_WG_place = RigidTransform(X_WO_place) @ X_OG

    def moved(X, p_W):
        return RigidTransform(X.rotation(), X.translation() + p_W)

    X = {"pre-grasp": moved(X_WG, -config.pregrasp_distance * y_G),
         "grasp": X_WG,
         "lift": moved(X_WG, up),
         "pre-place": moved(X_WG_place, up),
         "place": X_WG_place,
         # Back out along the gripper's approach at the place (the object may have been turned
         # about the vertical there, turning the approach with it).
         "retreat": moved(X_WG_place, -config.retreat_distance * X_WG_place.rotation().col(1))}
    if R_turn is not None:
        X["retreat"] = moved(X_WG_place, config.retreat_distance
                             * turned_retreat(X_WG_place.rotation().col(1)))
    if pour is not None:  # over the bowl after the lift: upright, then tilted
        X_WO_pour, X_WO_tilted = pour
        order = list(X)
        at = order.index("lift") + 1
        poses = dict(pour=RigidTransform(X_WO_pour) @ X_OG)
        if X_WO_tilted is not None:  # pourIn holds it upright: no tilt
            poses["tilted"] = RigidTransform(X_WO_tilted) @ X_OG
        X = {n: (X[n] if n in X else poses[n]) for n in order[:at] + list(poses) + order[at:]}
    return _KeyPoses(X, X_OG.inverse(), np.asarray(X_WO_place, float), R_turn, pour_hold)


def _waypoint_configurations(arms: _Arms, key: _KeyPoses, seeds, config):
    """IK for the six key poses of one candidate: ({name: q}, failure reason or "").

    Each pose is checked on the plant that matches what the hand holds there, with the clearance
    of the motion around it; after the pre-grasp, the previous configuration is the first seed
    (the straight moves between them need nearby configurations)."""
    steps = {  # the plants are built only when a candidate gets that far
        "pre-grasp": (lambda: arms.free, config.min_distance),
        "grasp": (lambda: arms.grasp, config.contact_min_distance),
        "lift": (lambda: arms.carry(key.X_GO), config.min_distance),
        "pour": (lambda: arms.carry(key.X_GO), config.min_distance),
        "tilted": (lambda: arms.carry(key.X_GO), config.min_distance),
        "pre-place": (lambda: arms.carry(key.X_GO), config.min_distance),
        "place": (lambda: arms.carry(key.X_GO), config.contact_min_distance),
        "retreat": (lambda: arms.placed(key.X_WO_place), config.contact_min_distance),
    }
    poses: dict[str, np.ndarray] = {}
    previous = None
    for name, (make_arm, min_distance) in steps.items():
        if name not in key.X:
            continue
        arm = make_arm()
        step_seeds = seeds if previous is None else [previous] + seeds
        r = solve_ik_seeds(arm, key.X[name], step_seeds,
                           position_tolerance=config.ik_position_tolerance,
                           angle_tolerance=config.ik_angle_tolerance, min_distance=min_distance)
        if not r.success:
            return poses, f"{name} pose unreachable ({r.reason})"
        poses[name] = r.q
        chain = ENTERED_FREE.get(name, ())
        if chain and chain[0] in poses and _jump(r.q, poses[chain[0]]) > BRANCH_JUMP:
            # The straight move's end is on another IK branch than its start: solve the straight
            # moves' poses before it again, back to the free move, each from the next one's
            # configuration, and let the free move make the turn.
            again, q_next = {}, r.q
            for start in chain:
                make_start, start_distance = steps[start]
                s = solve_ik_seeds(make_start(), key.X[start], [q_next],
                                   position_tolerance=config.ik_position_tolerance,
                                   angle_tolerance=config.ik_angle_tolerance,
                                   min_distance=start_distance)
                if not s.success:
                    break
                again[start], q_next = s.q, s.q
            if len(chain) == 1 and chain[0] in again:
                if _jump(r.q, again[chain[0]]) < _jump(r.q, poses[chain[0]]):
                    poses[chain[0]] = again[chain[0]]
            elif len(again) == len(chain) and all(
                    _jump(a, b) <= BRANCH_JUMP
                    for a, b in zip([r.q, *again.values()], again.values(), strict=False)):
                poses.update(again)  # the whole chain on the end's branch
        previous = r.q
    return poses, ""


# The straight moves that a free move leads into (end → the poses of the straight moves before
# it, back to the free move's end): a branch change between an end and its start is made up by
# solving those again from the end's configuration (`_waypoint_configurations`). The lift
# follows the approach: a grasp with a wrist joint at its limit lifts on another branch (joint 5
# turning ~2.9 rad during a 15 cm lift at the contact speed limits: a 9 s lift).
ENTERED_FREE = {"grasp": ("pre-grasp",), "lift": ("grasp", "pre-grasp"),
                "place": ("pre-place",)}
BRANCH_JUMP = np.pi / 2  # [rad] a joint turning more than this between the two ends of a 10 cm
# straight move is on another branch of the inverse kinematics (a wrist flip turns joints 5–7 by
# about π); the straight move through it then takes many seconds at the contact speed limits.


def _jump(q_a: np.ndarray, q_b: np.ndarray) -> float:
    """[rad] the largest joint change between two iiwa configurations."""
    return float(np.max(np.abs(np.asarray(q_a) - np.asarray(q_b))))


def _line(key: _KeyPoses, a: str, b: str) -> StraightLine:
    return StraightLine(key.X[a].translation(), key.X[b].translation(), key.X[a].rotation())


def _pour_moves(carry: ArmPlant, c: PlannerConfig, *, tilt: bool) -> list[tuple]:
    """The carrying moves of a pour: to the pour pose, tilt and tilt back (pourOut), on to the
    pre-place."""
    tilts = [("tilt", "pour", "tilted", carry, c.min_distance, c.carry_limits, None),
             ("untilt", "tilted", "pour", carry, c.min_distance, c.carry_limits, None)]
    return ([("carry", "lift", "pour", carry, c.min_distance, c.carry_limits, None)]
            + (tilts if tilt else [])
            + [("return", "pour", "pre-place", carry, c.min_distance, c.carry_limits, None)])


def _trajectories(arms: _Arms, q_start, poses, key: _KeyPoses, config, seeds, *, candidate,
                  part, receiving=None):
    """The segments between the key configurations, assembled into a Plan: (Plan, "", True) or
    (None, reason, whether the pick motions were found). `receiving`: a pass's receiver motion
    (`_receiving`: plan times of the arrival and of the lift's end → HandoverMotion and the
    receiver's hold duration); the robot holds the object at the
    hand-over pose until the receiver has closed, and the plan lasts until the receiver has held
    it alone for its `hold_duration`."""
    c = config
    carry = arms.carry(key.X_GO)
    # name, from, to, plant, clearance, limits, straight line or None (free: via-point guesses)
    moves = [
        ("move", "start", "pre-grasp", arms.free, c.min_distance, c.free_limits, None),
        ("approach", "pre-grasp", "grasp", arms.grasp, c.contact_min_distance, c.contact_limits,
         _line(key, "pre-grasp", "grasp")),
        ("lift", "grasp", "lift", arms.grasp, c.contact_min_distance, c.contact_limits,
         _line(key, "grasp", "lift")),
        *(_pour_moves(carry, c, tilt="tilted" in key.X) if "pour" in key.X else
          [("carry", "lift", "pre-place", carry, c.min_distance, c.carry_limits, None)]),
        ("descend", "pre-place", "place", carry, c.contact_min_distance, c.contact_limits,
         _line(key, "pre-place", "place")),
        ("retreat", "place", "retreat", arms.placed(key.X_WO_place), c.contact_min_distance,
         c.contact_limits,
         _line(key, "place", "retreat")),
    ]
    q = dict(poses, start=np.asarray(q_start, float))
    solved = {}
    for name, a, b, arm, min_distance, limits, line in moves:
        segment = plan_segment(arm, q[a], q[b], min_distance=min_distance, limits=limits,
                               config=c.segment, line=line, via=seeds if line is None else ())
        if not segment.success:
            return None, f"{name} trajectory: {segment.reason}", name not in PICK_MOTIONS
        solved[name] = segment

    # The timeline: move, approach, close, lift, carry, descend, open, retreat.
    pieces, rows = [], []
    t = 0.0

    def add_motion(name):
        nonlocal t
        s = solved[name]
        pieces.append(shifted(s.trajectory, t))
        rows.append((name, t, t + s.duration, s.min_clearance))
        t += s.duration

    def add_hold(q_hold, duration):
        nonlocal t
        pieces.append(PiecewisePolynomial.ZeroOrderHold(
            [t, t + duration], np.column_stack([q_hold, q_hold])))
        t += duration

    add_motion("move")
    add_motion("approach")
    t_close = t
    add_hold(q["grasp"], c.close_duration + c.settle_duration)
    t_grasp_closed = t
    add_motion("lift")
    t_lift_done = t
    add_motion("carry")
    t_pour = None
    if "tilted" in key.X:  # tilt over the bowl, hold, tilt back, on to the place
        add_motion("tilt")
        t_pour = (t, t + key.pour_hold)
        add_hold(q["tilted"], key.pour_hold)
        add_motion("untilt")
        add_motion("return")
    elif "pour" in key.X:  # held under the dispenser, on to the place
        t_pour = (t, t + key.pour_hold)
        add_hold(q["pour"], key.pour_hold)
        add_motion("return")
    t_descend = t
    add_motion("descend")
    motion = None
    if receiving is not None:  # a pass: held until the receiver has closed
        motion, hold_after = receiving(t, t_lift_done)
        add_hold(q["place"], max(motion.t_closed - t, 0.0))
    t_open = t
    add_hold(q["place"], c.squeeze_duration + c.open_duration
             + (0.0 if receiving is not None else c.release_dwell))
    t_opened = None if receiving is not None else t - c.release_dwell
    t_place_done = t
    add_motion("retreat")
    if motion is not None and t < t_place_done + hold_after:
        add_hold(q["retreat"], t_place_done + hold_after - t)
    q_traj = CompositeTrajectory(pieces)
    knots = [(0.0, c.open_width), *_closing(t_close, c), *_releasing(t_open, c),
             (t, c.open_width)]
    width_traj = PiecewisePolynomial.FirstOrderHold([k for k, _ in knots],
                                                    np.array([[w for _, w in knots]]))
    plan = Plan(q_traj=q_traj, v_traj=q_traj.MakeDerivative(), width_traj=width_traj,
                t_grasp_closed=t_grasp_closed, t_lift_done=t_lift_done,
                t_place_done=t_place_done, duration=t, candidate=candidate, part=part,
                X_WG_grasp=key.X["grasp"].GetAsMatrix4(),
                X_WO_place=key.X_WO_place, waypoints=q, segments=tuple(rows),
                R_turn=key.R_turn, t_pour=t_pour, t_descend=t_descend,
                t_handover=None if motion is None else (motion.t_closed, t_place_done),
                handover=motion, t_opened=t_opened)
    return plan, "", True


def _receiving(handover: Handover, candidates: GraspCandidates, target: ObjectDescription,
               part: str, X_WO, X_WO_handover, key: _KeyPoses, config: PlannerConfig,
               table_z: float, category, cache: dict | None = None,
               arm_p_W: np.ndarray | None = None):
    """A pass's receiver for one hand-over pose: (plan time of the robot's arrival →
    (HandoverMotion, hold_duration), "") or (None, why): the receiver's grasp on the part the
    logic names for it, given the robot's `part` (tg_drake.logic.receive), chosen by the
    feasibility core clear of the robot's gripper and the table (planning.handover)."""
    shown = tuple(PART_LABELS[k] for k in np.unique(np.asarray(candidates.parts, int)))
    parts = receiver_parts(category, held=part, parts=shown)
    grasp, why = choose_receiver_grasp(
        candidates, target=target, X_WO=X_WO, X_WO_handover=X_WO_handover,
        X_WG_robot=key.X["place"].GetAsMatrix4(), receiver_parts=parts, handover=handover,
        table_z=table_z, retreat=config.retreat_distance, cache=cache, arm_p_W=arm_p_W)
    if grasp is None:
        return None, why
    hold = handover.config.hold_duration
    X_WG_place = key.X["place"].GetAsMatrix4()
    return (lambda t, t_lifted: (receiver_motion(handover, grasp, t_arrive=t,
                                                 t_earliest=t_lifted, X_WG_robot=X_WG_place),
                                 hold)), ""
