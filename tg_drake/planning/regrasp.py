"""Place-and-regrasp for the p&pIn* tasks: where no grasp's wrist turn brings the object into the
task's resting pose at the place target, a first leg puts it down in an intermediate resting pose
from which a new grasp can.

    result = plan_task_leg(scene, candidates, place_xy=xy, q_start=q, placing=placing,
                           regrasp=True, ...)
    result.plan.regrasp  # True: a first leg; the supervisor looks again and plans the next one

The intermediate pose is chosen by trying, not by a rule per object. The poses tried: every
resting pose the perceived object can take (`POSES`: the one it is in, turned about the vertical
by `TaskMotionConfig.regrasp_yaws`, then the others but the task's own), at each of
`regrasp_spots` (fractions of the way from where it is to the place target; a spot where another
perceived object stands is left out), the smallest turn of the object first (`intermediates`).
For each, in order, the perceived object is moved there rigidly (points, frame, part boxes) and
given the pre-grasp hypotheses perception would make for it, with the feasibility stage's
approach variants (and, when its pose label stays, the current candidates moved with it); the
second leg is *reachable* when one of them, on a part the current candidates grasp, has
inverse-kinematics solutions for every key pose of the task's turned place (the feasibility
stage's geometric refusals, the planner's turns and waypoint IK; its motions are planned when
the leg is). For the first such intermediate poses (at most `regrasp_max_legs`, of
`regrasp_max_poses` examined), the first
leg is planned in full: picked with the current candidates (each followed by its
finger-swapped twin, the same grasp: the wrist's last joint cannot turn a half turn about the
vertical otherwise), placed in exactly that orientation, then the arm moved back to its start
configuration, out of the camera's view, so that perception can look again. An object lying at
the far edge of the reach, to be stood up, is so put down nearer, lying as it was, and picked
again.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from pydrake.math import RigidTransform
from pydrake.trajectories import CompositeTrajectory, PiecewisePolynomial

from tg_drake.grasping.expansion import ExpansionConfig, executed_poses
from tg_drake.grasping.feasibility import FeasibilityConfig, geometric_refusal
from tg_drake.perception.config import PregraspConfig
from tg_drake.perception.pregrasp import part_pregrasps
from tg_drake.planning.ik import budget_spent, ik_solves, solve_budget
from tg_drake.planning.planner import (
    PICK_POSES,
    TURNED_IN_HAND,
    PlannerConfig,
    PlanResult,
    _Arms,
    _key_poses,
    _seeds,
    _task_place_variants,
    _waypoint_configurations,
    budget_reason,
    carried_box,
    place_pose,
    plan_for_scene,
    plan_pick_and_place,
    target_shapes,
)
from tg_drake.planning.task_motion import (
    UP,
    TaskPlacing,
    axis_angle,
    perceived_pose,
    smallest_turn,
)
from tg_drake.planning.trajectory import plan_segment, shifted
from tg_drake.types import (
    PART_LABELS,
    POSES,
    GraspCandidates,
    ObjectDescription,
    moved_rigidly,
)

# How many pre-grasp hypotheses of the moved object the second leg's reach check tries.
SECOND_LEG_GRASPS = 24


@dataclass(frozen=True)
class Intermediate:
    """An intermediate resting pose: its label, its turn about the vertical [rad] from the
    smallest tip-over into it, and the object's frame there (4×4, its box resting on the
    support)."""

    pose: str
    yaw: float
    X_WO: np.ndarray


def intermediate_poses(X_WO: np.ndarray, extents, *, task_pose: str, is_tool: bool,
                       support_z: float, yaws, xy=None, poses=POSES) -> list[Intermediate]:
    """The intermediate resting poses to try (module doc) with the object's box centre at world
    `xy` (None: where it is), in order: the pose the object is in first (turned about the
    vertical only), then the others but the task's; each turned by `yaws` [rad] (the current
    pose without a turn is left out where the object stays: it is where it is)."""
    X_WO = np.asarray(X_WO, float)
    R = X_WO[:3, :3]
    current = perceived_pose(R, is_tool=is_tool)
    stays = xy is None or np.allclose(xy, X_WO[:2, 3], atol=1e-3)
    xy = X_WO[:2, 3] if xy is None else np.asarray(xy, float)
    out = []
    for pose in [current] + [p for p in poses if p != current]:
        if pose == task_pose:
            continue
        tip = smallest_turn(R, pose, is_tool=is_tool)
        if tip is None:
            continue
        for yaw in ([0.0] if pose != current or not stays else []) + [float(y) for y in yaws]:
            X = np.eye(4)
            X[:3, :3] = axis_angle(UP, yaw) @ tip @ R
            X = place_pose(X, extents, xy, table_z=support_z, release_height=0.0)
            if not any(np.allclose(X, o.X_WO, atol=1e-6) for o in out):
                out.append(Intermediate(pose, yaw, X))
    return out


def moved_object(target: ObjectDescription, X_WO_new: np.ndarray,
                 pregrasp: PregraspConfig | None = None) -> ObjectDescription:
    """The perceived object moved rigidly to frame X_WO_new: its points, normals, frame and part
    boxes, its pose label from the new frame, and the pre-grasp hypotheses of its moved part
    boxes (as perception makes them)."""
    T = np.asarray(X_WO_new, float) @ np.linalg.inv(np.asarray(target.X_WO, float))
    moved = moved_rigidly(target, T)
    X_WG, parts = part_pregrasps({n: (b.X_WB, b.half_extents) for n, b in moved.part_boxes.items()},
                                 PART_LABELS.index, pregrasp)
    return dataclasses.replace(
        moved, X_WO=np.asarray(X_WO_new, float),
        pose=perceived_pose(T[:3, :3] @ np.asarray(target.X_WO)[:3, :3], is_tool=target.is_tool),
        pregrasp_X_WG=X_WG, pregrasp_parts=np.asarray(parts, int))


def _second_leg_grasps(moved: ObjectDescription, table_z: float, carried=None, *,
                       approach: float) -> tuple[np.ndarray, np.ndarray]:
    """The grasps the second leg's reach check tries: `carried` first ((X_WG, part labels): the
    current candidates moved with the object, when its resting pose keeps its label), then the
    poses that may be executed for the moved object's pre-grasp hypotheses, as the scoring stage
    makes them (`tg_drake.grasping.expansion.executed_poses`, the planner's approach
    `approach` [m])."""
    poses, labels = [], []
    if carried is not None:
        poses += list(carried[0])
        labels += list(carried[1])
    hypotheses = np.asarray(moved.pregrasp_X_WG, float).reshape(-1, 4, 4)
    X_WG, source = executed_poses(hypotheses, table_z, approach_distance=approach,
                                  config=ExpansionConfig())
    poses += list(X_WG)
    labels += [int(k) for k in np.asarray(moved.pregrasp_parts, int)[source]]
    return np.asarray(poses, float).reshape(-1, 4, 4), np.asarray(labels, int)


def second_leg_reachable(moved: ObjectDescription, parts, *, placing: TaskPlacing, obstacles,
                         surfaces, config: PlannerConfig, scenario, table_z: float, q_start,
                         carried=None, max_grasps: int = SECOND_LEG_GRASPS,
                         feasibility: FeasibilityConfig | None = None) -> str:
    """Why no grasp of the object in its intermediate pose (`moved_object`; `_second_leg_grasps`
    with `carried`), on one of `parts` (in order), reaches every key pose of the task's place
    ("" when one does):
    the feasibility stage's geometric refusals (`feasibility`: its config, default
    FeasibilityConfig()), the task's turns and place yaws, inverse kinematics of each key
    pose (the motions between them are planned when the second leg is)."""
    feasibility = feasibility or FeasibilityConfig()
    X_WG_all, labels = _second_leg_grasps(moved, table_z, carried,
                                          approach=config.pregrasp_distance)
    order = [i for part in parts for i in np.flatnonzero(labels == PART_LABELS.index(part))]
    if not order:
        return "no pre-grasp hypothesis on " + ", ".join(parts)
    X_WO = np.asarray(moved.X_WO, float)
    held = carried_box(moved)
    X_place0 = place_pose(X_WO, held.size, placing.place_xy, table_z=placing.support_z,
                          release_height=config.release_height, X_OB=held.X_OB)
    boxes = [(f"object{i}", RigidTransform(o.X_WO), tuple(o.extents))
             for i, o in enumerate(obstacles)]
    boxes += [(f"surface_{s.name}", RigidTransform(np.asarray(s.X_WB)), tuple(s.size))
              for s in surfaces]
    arms = _Arms(scenario, config.open_width, boxes, target_shapes(moved), held.size,
                 X_WO=X_WO, X_OB=held.X_OB)
    seeds = _seeds(q_start, config.seed_postures, float(np.arctan2(X_WO[1, 3], X_WO[0, 3])))
    centroid = np.asarray(moved.p_W, float).mean(axis=0) if len(moved.p_W) else None
    why = ""
    for i in order[:max_grasps]:
        if budget_spent():  # (plan_task_leg's reason names the budget)
            return why or "not examined"
        part = PART_LABELS[int(labels[i])]
        X_WG = X_WG_all[i]
        refusal = geometric_refusal(moved, part, X_WG, centroid, feasibility, table_z)
        if refusal:
            why = why or refusal
            continue
        for R_turn, X_place in _task_place_variants(X_place0, config, placing=placing,
                                                    X_WO=X_WO, X_WG=X_WG,
                                                    extents=held.size, X_OB=held.X_OB,
                                                    is_tool=moved.is_tool):
            key = _key_poses(arms, X_WG, X_WO, X_place, config, R_turn=R_turn)
            if any(key.X[n].translation()[2] < table_z for n in ("pre-grasp", "grasp")):
                why = why or "a pre-grasp under the table"
                break
            poses, failure = _waypoint_configurations(arms, key, seeds, config)
            if not failure:
                return ""
            why = failure if PICK_POSES <= set(poses) or not why else why
            if not PICK_POSES <= set(poses):
                break  # the pick itself fails: no place variant helps
    return why or "no hypothesis examined"


def intermediates(target: ObjectDescription, placing: TaskPlacing, obstacles=()
                  ) -> list[Intermediate]:
    """`intermediate_poses` at each of the placing's `regrasp_spots` (fractions of the way from
    the object to the place target), the smallest turn of the object first (a move without a
    turn before any turn), then by spot; spots where the object's box would stand on another
    perceived object's (their footprints' circumscribed circles overlap) are left out."""
    X_WO = np.asarray(target.X_WO, float)
    here, there = X_WO[:2, 3], np.asarray(placing.place_xy, float)
    radius = 0.5 * float(np.linalg.norm(target.extents))  # [m] the box's, any orientation
    found = []
    for f in placing.regrasp_spots:
        xy = (1.0 - f) * here + f * there
        if any(np.linalg.norm(np.asarray(o.X_WO)[:2, 3] - xy)
               < radius + 0.5 * float(np.linalg.norm(o.extents)) for o in obstacles):
            continue
        found += intermediate_poses(X_WO, target.extents, task_pose=placing.pose,
                                    is_tool=target.is_tool, support_z=placing.support_z,
                                    yaws=placing.regrasp_yaws, xy=xy)

    def turn(inter):  # [rad] the angle of the object's rotation into the intermediate pose
        R = inter.X_WO[:3, :3] @ X_WO[:3, :3].T
        return round(float(np.arccos(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0))), 6)

    return sorted(found, key=turn)  # stable: by spot within one turn


def plan_regrasp_leg(candidates: GraspCandidates, *, target: ObjectDescription, obstacles=(),
                     q_start, table_z: float, placing: TaskPlacing, direct: PlanResult,
                     config: PlannerConfig | None = None, scenario=None, exclude_parts=(),
                     max_parts: int | None = None, surfaces=(),
                     feasibility: FeasibilityConfig | None = None) -> PlanResult:
    """A place-and-regrasp's first leg (module doc) for the p&pIn* `placing` whose direct plan
    `direct` failed: a plan that puts the object down in an intermediate resting pose and moves
    the arm back to `q_start` (`Plan.regrasp`), or `direct` with the reason none was found."""
    config = config or PlannerConfig()
    X_WO = np.asarray(target.X_WO, float)
    scores = np.asarray(candidates.score, float)
    parts = []
    for i in np.argsort(-scores, kind="stable"):
        name = PART_LABELS[int(candidates.parts[i])]
        if scores[i] > 0 and name not in exclude_parts and name not in parts:
            parts.append(name)
    if max_parts is not None:
        parts = parts[:max_parts]
    twins = finger_swapped(candidates)
    tried, planned_legs = [], 0
    total_time = direct.planning_time
    for inter in intermediates(target, placing, obstacles)[:placing.regrasp_max_poses]:
        if budget_spent():  # (plan_task_leg's reason says so)
            break
        label = (f"{inter.pose} turned {np.rad2deg(inter.yaw):.0f} deg at "
                 f"({inter.X_WO[0, 3]:.3f}, {inter.X_WO[1, 3]:.3f}) m")
        carried = None
        if inter.pose == target.pose:  # the current candidates, moved with the object
            T = inter.X_WO @ np.linalg.inv(X_WO)
            keep = np.asarray(candidates.score, float) > 0
            carried = (T @ np.asarray(candidates.X_WG, float)[keep],
                       np.asarray(candidates.parts, int)[keep])
        why = second_leg_reachable(moved_object(target, inter.X_WO), parts, placing=placing,
                                   obstacles=obstacles, surfaces=surfaces, config=config,
                                   scenario=scenario, table_z=table_z, q_start=q_start,
                                   carried=carried, feasibility=feasibility)
        if why:
            tried.append(f"{label}: the next grasp cannot ({why})")
            continue
        leg = dataclasses.replace(placing, pose=inter.pose, place_xy=tuple(inter.X_WO[:2, 3]),
                                  R_place=tuple(map(tuple, inter.X_WO[:3, :3])))
        result = plan_pick_and_place(
            twins, target=target, obstacles=obstacles, place_xy=leg.place_xy,
            q_start=q_start, table_z=table_z, config=dataclasses.replace(config, place_yaws=[0.0]),
            scenario=scenario, exclude_parts=exclude_parts, max_parts=max_parts, placing=leg,
            surfaces=surfaces)
        total_time += result.planning_time
        planned_legs += 1
        if result.status == "planned":
            plan, why = _back_to_start(result.plan, q_start, target, obstacles, surfaces,
                                       config, scenario)
            if plan is not None:  # the candidate's index in `candidates`, not in `twins`
                plan = dataclasses.replace(plan, candidate=plan.candidate // 2)
                return dataclasses.replace(result, plan=plan, planning_time=total_time,
                                           candidate=plan.candidate,
                                           costs=result.costs.reshape(-1, 2).min(axis=1),
                                           candidate_reasons=result.candidate_reasons[::2])
        else:
            why = result.reason
        tried.append(f"{label}: this leg cannot ({why})")
        if planned_legs >= placing.regrasp_max_legs:
            break
    detail = "; ".join(tried[:4]) + (f"; … ({len(tried)} tried)" if len(tried) > 4 else "")
    return dataclasses.replace(
        direct, planning_time=total_time,
        reason=f"{direct.reason}; no place-and-regrasp found: {detail or 'no intermediate pose'}")


# The WSG's fingers are alike: a grasp turned half a turn about its approach axis y_G (through
# the grasp point, on that axis) is the same grasp with the fingers swapped.
SWAP_FINGERS = np.diag([-1.0, 1.0, -1.0, 1.0])


def finger_swapped(candidates: GraspCandidates) -> GraspCandidates:
    """The candidates with each one followed by its finger-swapped twin (`SWAP_FINGERS`), same
    scores and source: the first leg may turn the object half a turn about the vertical, which
    the wrist's last joint reaches only from the twin. Row 2i is candidate i, 2i + 1 its twin."""
    c = candidates
    X = np.asarray(c.X_WG, float)
    X_twins = np.stack([X, X @ SWAP_FINGERS], axis=1).reshape(-1, 4, 4)

    def twice(a):
        return None if a is None else np.repeat(np.asarray(a), 2, axis=0)

    reasons = tuple(r for r in c.feasibility_reasons for _ in range(2))
    source = twice(np.arange(len(c.score)) if c.source is None else c.source)
    return dataclasses.replace(c, X_WG=X_twins, parts=twice(c.parts), p_part=twice(c.p_part),
                               p_local=twice(c.p_local), score=twice(c.score),
                               p_hold=twice(c.p_hold), feasibility_reasons=reasons,
                               source=source)


def _back_to_start(plan, q_start, target: ObjectDescription, obstacles, surfaces,
                   config: PlannerConfig, scenario, *, regrasp: bool = True):
    """`plan` with a free move from its retreat back to `q_start` appended, the gripper open,
    marked `Plan.regrasp` = `regrasp`: (Plan, "") or (None, why)."""
    boxes = [(f"object{i}", RigidTransform(o.X_WO), tuple(o.extents))
             for i, o in enumerate(obstacles)]
    boxes += [(f"surface_{s.name}", RigidTransform(np.asarray(s.X_WB)), tuple(s.size))
              for s in surfaces]
    arms = _Arms(scenario, config.open_width, boxes, target_shapes(target), target.extents,
                 X_WO=target.X_WO)  # (only `placed`: nothing is carried on the way back)
    q_end = plan.q(plan.duration)
    seeds = _seeds(q_start, config.seed_postures, 0.0)
    segment = plan_segment(arms.placed(plan.X_WO_place), q_end, np.asarray(q_start, float),
                           min_distance=config.min_distance, limits=config.free_limits,
                           config=config.segment, via=seeds)
    if not segment.success:
        return None, f"back to the start: {segment.reason}"
    t0 = plan.duration
    pieces = [plan.q_traj.segment(k) for k in range(plan.q_traj.get_number_of_segments())]
    q_traj = CompositeTrajectory(pieces + [shifted(segment.trajectory, t0)])
    breaks = list(plan.width_traj.get_segment_times())
    widths = [float(plan.width_traj.value(t)[0, 0]) for t in breaks]
    width_traj = PiecewisePolynomial.FirstOrderHold(
        breaks + [t0 + segment.duration], np.array([widths + [widths[-1]]]))
    return dataclasses.replace(
        plan, q_traj=q_traj, v_traj=q_traj.MakeDerivative(), width_traj=width_traj,
        duration=t0 + segment.duration, regrasp=regrasp,
        waypoints=dict(plan.waypoints, home=np.asarray(q_start, float)),
        segments=plan.segments + (("home", t0, t0 + segment.duration, segment.min_clearance),)
    ), ""


def plan_task_leg(scene, candidates: GraspCandidates, *, place_xy, q_start, regrasp: bool = False,
                  return_home: bool = False, **kwargs) -> PlanResult:
    """`tg_drake.planning.planner.plan_for_scene`, and where a p&pIn* task's turn in the hand
    cannot be placed: with `regrasp`, a place-and-regrasp's first leg (`plan_regrasp_leg`);
    without, the reason says that none was allowed (`feasibility`: the feasibility stage's config,
    whose geometric refusals judge the second leg's grasps). With `return_home` every plan ends
    with the arm back at `q_start` (a regrasp leg does anyway). The whole request keeps within the
    budget `PlannerConfig.max_ik_solves`; `PlanResult.ik_solves` says what it used."""
    config = kwargs.get("config") or PlannerConfig()
    n0 = ik_solves()
    with solve_budget(config.max_ik_solves):
        result = _plan_task_leg(scene, candidates, place_xy=place_xy, q_start=q_start,
                                regrasp=regrasp, return_home=return_home, **kwargs)
        spent = budget_spent()
    out = spent and result.status != "planned"
    reason = result.reason + (f" (then {budget_reason(config)})" if out else "")
    return dataclasses.replace(result, ik_solves=ik_solves() - n0, out_of_budget=out,
                               reason=reason)


def _plan_task_leg(scene, candidates: GraspCandidates, *, place_xy, q_start, regrasp: bool,
                   return_home: bool, feasibility: FeasibilityConfig | None = None,
                   **kwargs) -> PlanResult:
    result = plan_for_scene(scene, candidates, place_xy=place_xy, q_start=q_start, **kwargs)
    if result.status == "planned" and return_home:
        target = scene.objects[candidates.target]
        others = [o for i, o in enumerate(scene.objects) if i != candidates.target]
        config = kwargs.get("config") or PlannerConfig()
        plan, why = _back_to_start(result.plan, q_start, target, others, kwargs.get("surfaces", ()),
                                   config, kwargs.get("scenario"), regrasp=False)
        if plan is None:
            return dataclasses.replace(result, status="unreachable", plan=None, reason=why,
                                       candidate=None, part=None)
        return dataclasses.replace(result, plan=plan)
    placing = kwargs.get("placing")
    if (result.status == "planned" or placing is None or placing.pose is None
            or placing.R_place is not None or TURNED_IN_HAND not in result.reason):
        return result
    if not regrasp:
        return dataclasses.replace(result, reason=result.reason + (
            " (no place-and-regrasp leg allowed: pipeline.supervisor.max_regrasps)"))
    target = scene.objects[candidates.target]
    others = [o for i, o in enumerate(scene.objects) if i != candidates.target]
    # (a pass's hand-over and the receiver's category do not apply to a p&pIn* task's legs)
    kwargs = {k: v for k, v in kwargs.items() if k not in ("placing", "handover", "category")}
    return plan_regrasp_leg(candidates, target=target, obstacles=others, q_start=q_start,
                            table_z=float(scene.X_WT[2, 3]), placing=placing, direct=result,
                            feasibility=feasibility, **kwargs)
