"""Inverse kinematics for the iiwa + WSG: joint positions that put the gripper frame G at a pose.

The arm model for planning is a separate plant (`make_arm_plant`): the iiwa, the WSG welded to its
flange with its fingers fixed open, the table (those models of the scenario's directives, through
`tg_drake.robot_plants`), optional obstacles (boxes) welded where the perceived objects are, and
optionally a held object (a box welded to the gripper frame G).
Collision avoidance uses minimum-distance constraints on that plant; `clearance` measures the
smallest signed distance of a configuration for checking a path after it is planned.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np
from pydrake.geometry import Box, CollisionFilterDeclaration, Cylinder, GeometrySet, Sphere
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.plant import CoulombFriction
from pydrake.multibody.tree import SpatialInertia
from pydrake.planning import RobotDiagramBuilder
from pydrake.solvers import SnoptSolver, Solve, SolverOptions

from tg_drake.robot import (
    IIWA_HOME,
    IIWA_JOINT_NAMES,
    WRIST_OFFSET_G,
    WSG_BODY,
    WSG_FINGER_JOINTS,
    WSG_FINGERS,
    WSG_MAX_OPENING,
    wrist_reach_margin,
)
from tg_drake.robot_plants import add_scenario_models
from tg_drake.table import TABLE_SIZE, X_WT_DEFAULT, add_table

# The scenario's models in the planning plant: the robot and the gripper (the table is added from
# the scenario's table_size); loose objects become obstacles if at all.
PLANNING_MODELS = ("iiwa", "wsg")

# The IK's default pose tolerances: [m] per axis of G's position, [rad] of its orientation.
IK_POSITION_TOLERANCE = 0.002
IK_ANGLE_TOLERANCE = 0.02

# Weight of the IK's pull towards its seed [1/rad²]: a preference among the solutions that meet
# the (hard) pose and clearance constraints.
IK_SEED_WEIGHT = 0.01


@dataclass
class ArmPlant:
    diagram: object
    plant: object
    scene_graph: object
    context: object  # diagram context
    plant_context: object
    G: object  # the WSG body frame
    iiwa: object  # model instance
    obstacles: list  # (name, X_WB, size) boxes added as obstacles
    iiwa_indices: np.ndarray = None  # (7,) positions of the iiwa joints in the plant's q
    q_fingers: np.ndarray = None  # (nq,) plant positions with the fingers at the opening (iiwa 0)
    X_BW: np.ndarray = field(default_factory=lambda: np.eye(4))  # 4×4 world → the iiwa's base
    # (link 0) frame
    kinematics: bytes = b""  # a fingerprint of what an IK without clearance constraints depends
    # on (`_kinematics`): arm plants that differ only in their obstacles share it

    def full_q(self, q_iiwa) -> np.ndarray:
        """The plant's position vector for iiwa joint positions `q_iiwa` (fingers as held)."""
        q = self.q_fingers.copy()
        q[self.iiwa_indices] = q_iiwa
        return q


def make_arm_plant(scenario = None, *, obstacles=(),
                   finger_opening: float = WSG_MAX_OPENING, held=None,
                   finger_contact=()) -> ArmPlant:
    """A kinematic model of the arm for IK and collision checking.

    obstacles: iterable of (name, X_WB RigidTransform, size) welded to the world: a box when size
        is (sx, sy, sz), a cylinder along z when it is (radius, length).
    held: None, or (X_GO RigidTransform, (sx, sy, sz)): a box carried in the hand, welded to the
        gripper frame G. It never collides with the gripper or links 6–7 (it is in the hand), and
        it does collide with the rest of the arm, the table and the obstacles.
    finger_contact: names of obstacles the two finger pads may overlap (the object being grasped
        or released: its box is a bounding box, and the fingers close on the object inside it);
        the rest of the arm and gripper still keeps clear of them.
    """
    builder = RobotDiagramBuilder(time_step=0.0)
    plant, scene_graph = builder.plant(), builder.scene_graph()
    add_scenario_models(plant, scenario, PLANNING_MODELS)
    if scenario is not None:
        add_table(plant, scenario.table_size, scenario.X_WT.GetDeterministicValue())
    else:  # the station's default table
        add_table(plant, TABLE_SIZE, X_WT_DEFAULT)
    # Fix the fingers at the given opening: weld-like by locking their joints in IK (bounds).
    world = plant.world_body()
    added = []
    touchable = []
    for name, X_WB, size in obstacles:
        instance = plant.AddModelInstance(f"obstacle_{name}")
        body = plant.AddRigidBody(f"obstacle_{name}", instance, SpatialInertia.SolidBoxWithMass(
            1.0, *(size if len(size) == 3 else (2 * size[0], 2 * size[0], size[1]))))
        # (sx, sy, sz): a box; (radius, length): a cylinder along the obstacle frame's z.
        shape = Box(*size) if len(size) == 3 else Cylinder(*size)
        plant.RegisterCollisionGeometry(body, RigidTransform(), shape, f"obstacle_{name}",
                                        CoulombFriction(0.5, 0.5))
        plant.WeldFrames(world.body_frame(), body.body_frame(), X_WB)
        added.append((name, X_WB, size))
        if name in finger_contact:
            touchable.append(body)
    unknown = set(finger_contact) - {name for name, _, _ in added}
    if unknown:
        raise ValueError(f"finger_contact names unknown obstacle(s) {sorted(unknown)}; "
                         f"obstacles: {', '.join(name for name, _, _ in added)}")
    held_body = None
    if held is not None:
        X_GO, size = held
        instance = plant.AddModelInstance("held_object")
        held_body = plant.AddRigidBody("held_object", instance,
                                       SpatialInertia.SolidBoxWithMass(1.0, *size))
        plant.RegisterCollisionGeometry(held_body, RigidTransform(), Box(*size), "held_object",
                                        CoulombFriction(0.5, 0.5))
        plant.WeldFrames(plant.GetFrameByName(WSG_BODY, plant.GetModelInstanceByName("wsg")),
                         held_body.body_frame(), X_GO)
    plant.Finalize()
    # The gripper's own bodies never collide with each other or with link 7 (they are attached).
    wsg = plant.GetModelInstanceByName("wsg")
    iiwa = plant.GetModelInstanceByName("iiwa")
    manager = scene_graph.collision_filter_manager()
    gripper_geometries = GeometrySet(
        [g for b in plant.GetBodyIndices(wsg)
         for g in plant.GetCollisionGeometriesForBody(plant.get_body(b))]
        + list(plant.GetCollisionGeometriesForBody(plant.GetBodyByName("iiwa_link_7", iiwa)))
        + list(plant.GetCollisionGeometriesForBody(plant.GetBodyByName("iiwa_link_6", iiwa)))
        + (list(plant.GetCollisionGeometriesForBody(held_body)) if held_body else []))
    manager.Apply(CollisionFilterDeclaration().ExcludeWithin(gripper_geometries))
    if touchable:
        fingers = GeometrySet([g for n in WSG_FINGERS
                               for g in plant.GetCollisionGeometriesForBody(
                                   plant.GetBodyByName(n, wsg))])
        objects = GeometrySet([g for b in touchable
                               for g in plant.GetCollisionGeometriesForBody(b)])
        manager.Apply(CollisionFilterDeclaration().ExcludeBetween(fingers, objects))
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    plant_context = plant.GetMyMutableContextFromRoot(context)
    plant.SetPositions(plant_context, wsg, [-finger_opening / 2, finger_opening / 2])
    G = plant.GetFrameByName(WSG_BODY, wsg)
    iiwa_indices = np.array([plant.GetJointByName(n, iiwa).position_start()
                             for n in IIWA_JOINT_NAMES])
    X_WB = plant.EvalBodyPoseInWorld(plant_context, plant.GetBodyByName("iiwa_link_0", iiwa))
    q_fingers = plant.GetPositions(plant_context).copy()
    return ArmPlant(diagram, plant, scene_graph, context, plant_context, G, iiwa, added,
                    iiwa_indices, q_fingers, X_WB.inverse().GetAsMatrix4(),
                    _kinematics(plant, G, iiwa_indices, q_fingers))


def _kinematics(plant, G, iiwa_indices, q_fingers) -> bytes:
    """A fingerprint of the arm plant's kinematics as the IK sees them without clearance
    constraints: the joint limits, the fingers' positions and G's pose in the world at three
    configurations (any change of the chain, its mounting or the gripper's frame changes them)."""
    context = plant.CreateDefaultContext()
    parts = [plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits(), q_fingers]
    for q_iiwa in (np.array(IIWA_HOME), np.zeros(7), np.linspace(0.3, -0.3, 7)):
        q = q_fingers.copy()
        q[iiwa_indices] = q_iiwa
        plant.SetPositions(context, q)
        parts.append(G.CalcPoseInWorld(context).GetAsMatrix4())
    return hashlib.sha1(b"".join(np.ascontiguousarray(p, float).tobytes()
                                 for p in parts)).digest()


def clearance(arm: ArmPlant, q_iiwa, max_distance: float = 0.1) -> float:
    """The smallest signed distance [m] between unfiltered collision geometries of the arm plant
    at iiwa joint positions `q_iiwa` (negative: penetration); `max_distance` when every pair is
    farther apart than that."""
    arm.plant.SetPositions(arm.plant_context, arm.full_q(q_iiwa))
    query = arm.plant.get_geometry_query_input_port().Eval(arm.plant_context)
    pairs = query.ComputeSignedDistancePairwiseClosestPoints(max_distance)
    return min([max_distance] + [pair.distance for pair in pairs])


@dataclass
class IkResult:
    success: bool
    q: np.ndarray  # (7,) iiwa joint positions
    position_error: float  # [m] achieved vs requested gripper position
    reason: str = ""


def solve_ik(arm: ArmPlant, X_WG: RigidTransform, *, q_seed=IIWA_HOME,
             position_tolerance: float = IK_POSITION_TOLERANCE,
             angle_tolerance: float = IK_ANGLE_TOLERANCE,
             min_distance: float | None = 0.005, max_iterations: int = 100,
             q_guess=None) -> IkResult:
    """Joint positions putting G at X_WG within tolerances, inside joint limits and (when
    `min_distance` is given) with every collision pair at least that far apart.

    position_tolerance [m] and angle_tolerance [rad] bound the gripper's pose error.
    max_iterations bounds SNOPT's major iterations: a solvable IK converges in a few tens, and an
    unsolvable one with collision constraints can otherwise take a second to give up.
    q_guess: the solver's initial guess (default: q_seed); the cost always pulls towards q_seed.
    """
    plant = arm.plant
    ik = InverseKinematics(plant, arm.plant_context, with_joint_limits=True)
    q = ik.q()
    p = X_WG.translation()
    ik.AddPositionConstraint(arm.G, [0, 0, 0], plant.world_frame(),
                             p - position_tolerance, p + position_tolerance)
    ik.AddOrientationConstraint(arm.G, RotationMatrix(), plant.world_frame(), X_WG.rotation(),
                                angle_tolerance)
    if min_distance is not None:
        ik.AddMinimumDistanceLowerBoundConstraint(min_distance, 0.05)
    # The fingers stay where the arm plant holds them.
    wsg = plant.GetModelInstanceByName("wsg")
    q_all = plant.GetPositions(arm.plant_context)
    fingers = [plant.GetJointByName(n, wsg).position_start() for n in WSG_FINGER_JOINTS]
    prog = ik.prog()
    for i in fingers:
        prog.AddBoundingBoxConstraint(q_all[i], q_all[i], q[i])
    iiwa_idx = [plant.GetJointByName(n, arm.iiwa).position_start() for n in IIWA_JOINT_NAMES]
    q_nominal = q_all.copy()
    q_nominal[iiwa_idx] = q_seed if q_guess is None else q_guess
    prog.AddQuadraticErrorCost(np.eye(len(iiwa_idx)) * IK_SEED_WEIGHT, np.asarray(q_seed),
                               q[iiwa_idx])
    prog.SetInitialGuess(q, q_nominal)
    options = SolverOptions()
    options.SetOption(SnoptSolver().solver_id(), "Major iterations limit", max_iterations)
    result = Solve(prog, solver_options=options)
    _SOLVES.count += 1
    q_sol = result.GetSolution(q)
    plant.SetPositions(arm.plant_context, q_sol)
    err = float(np.linalg.norm(arm.G.CalcPoseInWorld(arm.plant_context).translation() - p))
    if not satisfies_constraints(result, prog):
        return IkResult(False, q_sol[iiwa_idx], err,
                        f"no inverse-kinematics solution ({result.get_solver_id().name()}: "
                        f"{result.get_solution_result().name})")
    return IkResult(True, q_sol[iiwa_idx], err)


# [constraint units: rad, m, and the minimum-distance penalty] SNOPT's default feasibility
# tolerance is 1e-6; we accept a little more than that.
CONSTRAINT_TOLERANCE = 1e-5


def satisfies_constraints(result, prog, tolerance: float = CONSTRAINT_TOLERANCE) -> bool:
    """Whether the solver's answer satisfies every constraint of `prog`.

    The costs only express a preference (stay near the seed; be fast), so an answer that SNOPT
    could not prove optimal ("current point cannot be improved") is still a valid solution when
    it is feasible; an infeasible answer fails this check whatever the solver said."""
    if result.is_success():
        return True
    x = result.get_x_val()
    return all(b.evaluator().CheckSatisfied(result.GetSolution(b.variables()), tolerance)
               for b in prog.GetAllConstraints()) and np.all(np.isfinite(x))


# [m] added to the tolerances' bound in `beyond_reach`: the solver's accepted constraint violation
# (1e-5 on the orientation constraint's cosine is about 2.5e-4 rad at 0.02 rad, 0.05 mm at the
# wrist's offset), with room to spare.
REACH_SLACK = 0.001


def beyond_reach(arm: ArmPlant, X_WG: RigidTransform, position_tolerance: float,
                 angle_tolerance: float) -> float:
    """[m] how far the wrist centre of gripper pose X_WG lies outside the arm's reachable shell
    (`tg_drake.robot.wrist_reach_margin`) beyond what an IK solution within the tolerances may
    move it (its position error, up to √3 × `position_tolerance` [m], and its turn, up to
    `angle_tolerance` [rad], about G at the wrist's offset; `REACH_SLACK` for the solver's
    constraint tolerance): > 0 means no joint configuration reaches the pose; 0 otherwise."""
    slack = (np.sqrt(3.0) * (position_tolerance + CONSTRAINT_TOLERANCE)
             + WRIST_OFFSET_G * angle_tolerance + REACH_SLACK)
    margin = wrist_reach_margin(arm.X_BW @ X_WG.GetAsMatrix4())
    return max(0.0, -margin - slack)


class _Solves:
    """The IK solver calls of this process (`count`) and where the planning budget open now
    ends (`limit`, a count; None: no budget)."""

    count = 0
    limit: int | None = None


_SOLVES = _Solves()


def ik_solves() -> int:
    """How many IK solver calls this process has made (remembered answers and poses refused
    as beyond reach are not solver calls)."""
    return _SOLVES.count


@contextlib.contextmanager
def solve_budget(n: int | None):
    """Within: `budget_spent()` is True once `n` more IK solver calls have been made (None: no
    budget). A budget opened inside another keeps the outer one: a planning request's budget
    covers every leg and check it plans."""
    if _SOLVES.limit is not None or n is None:
        yield
        return
    _SOLVES.limit = _SOLVES.count + int(n)
    try:
        yield
    finally:
        _SOLVES.limit = None


def budget_spent() -> bool:
    """Whether the open planning budget (`solve_budget`) has been used up."""
    return _SOLVES.limit is not None and _SOLVES.count >= _SOLVES.limit


# An IK without clearance constraints depends on the arm's kinematics (`ArmPlant.kinematics`),
# the pose, the seed and the tolerances only, not on the obstacles; a planning call asks for the
# same pose from many places (the pick poses again for each place variant, the place poses again
# for each spot of a place-and-regrasp). Its answers are kept for the process, the least recently
# used dropped beyond FREE_IK_MEMO entries (each under 1 kB).
FREE_IK_MEMO = 20_000
_free_ik_memo: OrderedDict = OrderedDict()


def _free_ik(arm: ArmPlant, X_WG: RigidTransform, q_seed, kwargs: dict) -> IkResult:
    """`solve_ik` from `q_seed` without clearance constraints, remembered (`FREE_IK_MEMO`);
    a copy, so that the caller may change it."""
    key = (arm.kinematics, X_WG.GetAsMatrix4().tobytes(),
           np.asarray(q_seed, float).tobytes(), tuple(sorted(kwargs.items())))
    result = _free_ik_memo.get(key) if arm.kinematics else None
    if result is None:
        result = solve_ik(arm, X_WG, q_seed=q_seed, min_distance=None, **kwargs)
        if arm.kinematics:
            _free_ik_memo[key] = result
            if len(_free_ik_memo) > FREE_IK_MEMO:
                _free_ik_memo.popitem(last=False)
    else:
        _free_ik_memo.move_to_end(key)
    return dataclasses.replace(result, q=result.q.copy())


def solve_ik_seeds(arm: ArmPlant, X_WG: RigidTransform, seeds, *,
                   min_distance: float | None = 0.005, **kwargs) -> IkResult:
    """`solve_ik` from each seed in turn (the IK is local): the first success, else the last
    failure. The seeds' order is a preference (the cost pulls a solution towards its seed).

    With `min_distance`, each seed first gets an IK without collision constraints (a few
    milliseconds, and it fails fast where the pose is out of reach); only its solution, when there
    is one and it differs from the ones already tried, starts the IK with the minimum-distance
    constraints. `kwargs` go to `solve_ik`.

    A pose whose wrist centre lies outside the arm's reachable shell by more than the pose
    tolerances let the solution move it (`beyond_reach`) fails at once, without a solver call.
    """
    if len(seeds) == 0:
        raise ValueError("solve_ik_seeds needs at least one seed")
    outside = beyond_reach(arm, X_WG, kwargs.get("position_tolerance", IK_POSITION_TOLERANCE),
                           kwargs.get("angle_tolerance", IK_ANGLE_TOLERANCE))
    if outside > 0.0:
        return IkResult(False, np.asarray(seeds[-1], float), outside,
                        f"out of reach within the joint limits (the wrist centre "
                        f"{1000 * outside:.0f} mm beyond the arm's reach)")
    result = None
    tried = []
    for q_seed in seeds:
        free = _free_ik(arm, X_WG, q_seed, kwargs)
        if min_distance is None or not free.success:
            result = free
            if free.success:
                return free
            continue
        if any(np.max(np.abs(free.q - q)) < 0.05 for q in tried):  # [rad] the same basin
            continue
        tried.append(free.q)
        result = solve_ik(arm, X_WG, q_seed=q_seed, q_guess=free.q, min_distance=min_distance,
                          **kwargs)
        if result.success:
            return result
    if tried:
        result.reason = (f"within reach, but no IK solution keeps {min_distance} m of clearance "
                         f"(tried from {len(tried)} configuration(s))")
    else:
        result.reason = f"out of reach within the joint limits (from {len(seeds)} seeds)"
    return result


def shape_surface_points(shape, spacing: float) -> np.ndarray:
    """(N, 3) points on the surface of a Box, Cylinder (along z) or Sphere in its own frame,
    about `spacing` [m] apart; (0, 3) for another shape."""
    if isinstance(shape, Sphere):
        r = shape.radius()
        n = max(8, int(np.ceil(4 * np.pi * r * r / spacing ** 2)))
        k = np.arange(n) + 0.5  # a Fibonacci sphere: near-even spacing
        z = 1 - 2 * k / n
        a = np.pi * (1 + 5 ** 0.5) * k
        rho = np.sqrt(1 - z * z)
        return r * np.column_stack([rho * np.cos(a), rho * np.sin(a), z])
    if isinstance(shape, Cylinder):
        r, length = shape.radius(), shape.length()
        a = np.linspace(0, 2 * np.pi, max(8, int(np.ceil(2 * np.pi * r / spacing))),
                        endpoint=False)
        z = np.linspace(-length / 2, length / 2, max(2, int(np.ceil(length / spacing)) + 1))
        A, Z = np.meshgrid(a, z, indexing="ij")
        side = np.column_stack([r * np.cos(A.ravel()), r * np.sin(A.ravel()), Z.ravel()])
        rings = [side]
        for radius in np.arange(spacing, r, spacing):  # the two end discs, ring by ring
            b = np.linspace(0, 2 * np.pi, max(6, int(np.ceil(2 * np.pi * radius / spacing))),
                            endpoint=False)
            for end in (-length / 2, length / 2):
                rings.append(np.column_stack([radius * np.cos(b), radius * np.sin(b),
                                              np.full(len(b), end)]))
        rings.append(np.array([[0.0, 0.0, -length / 2], [0.0, 0.0, length / 2]]))
        return np.concatenate(rings)
    if isinstance(shape, Box):
        half = np.array([shape.width(), shape.depth(), shape.height()]) / 2
        axes = [np.linspace(-h, h, max(2, int(np.ceil(2 * h / spacing)) + 1)) for h in half]
        grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        return grid[np.any(np.isclose(np.abs(grid), half, rtol=0, atol=1e-12), axis=1)]
    return np.zeros((0, 3))


def arm_surface_points(arm: ArmPlant, q_iiwa, *, spacing: float = 0.01) -> np.ndarray:
    """(N, 3) world points on the collision shapes of the iiwa's links in configuration `q_iiwa`
    (the gripper's are not included), about `spacing` [m] apart: what another body near the arm
    must stay clear of (the receiver of a pass)."""
    plant = arm.plant
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, arm.full_q(np.asarray(q_iiwa, float)))
    inspector = arm.scene_graph.model_inspector()
    out = []
    for index in plant.GetBodyIndices(arm.iiwa):
        body = plant.get_body(index)
        X_WB = plant.EvalBodyPoseInWorld(context, body)
        for g in plant.GetCollisionGeometriesForBody(body):
            p = shape_surface_points(inspector.GetShape(g), spacing)
            if len(p):
                X_WS = X_WB @ inspector.GetPoseInFrame(g)
                out.append(p @ X_WS.rotation().matrix().T + X_WS.translation())
    return np.concatenate(out) if out else np.zeros((0, 3))
