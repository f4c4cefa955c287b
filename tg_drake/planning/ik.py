"""Inverse kinematics for the iiwa + WSG: joint positions that put the gripper frame G at a pose.

The arm model for planning is a separate plant (`make_arm_plant`): the iiwa, the WSG welded to its
flange with its fingers fixed open, the table, and optional obstacles (boxes) welded where the
perceived objects are. Collision avoidance uses minimum-distance constraints on that plant.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.geometry import Box, CollisionFilterDeclaration, GeometrySet
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.parsing import ModelDirectives, ProcessModelDirectives
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, CoulombFriction
from pydrake.multibody.tree import SpatialInertia
from pydrake.solvers import Solve
from pydrake.systems.framework import DiagramBuilder

from tg_drake.scenario import IIWA_HOME, Scenario, default_directives


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


def make_arm_plant(scenario: Scenario | None = None, *, obstacles=(),
                   finger_opening: float = 0.11) -> ArmPlant:
    """A kinematic model of the arm for IK and collision checking.

    obstacles: iterable of (name, X_WB RigidTransform, (sx, sy, sz)) boxes welded to the world.
    """
    from tg_drake.station import make_parser

    scenario = scenario or Scenario()
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    parser = make_parser(plant)
    # Only the robot, the gripper and the table; loose objects become obstacles if at all.
    kept = {"iiwa", "wsg", "table"}
    directives = [d for d in (scenario.directives or default_directives())
                  if (d.add_model and d.add_model.name in kept)
                  or (d.add_weld and d.add_weld.child.split("::")[0] in kept)]
    ProcessModelDirectives(ModelDirectives(directives=directives), parser)
    # Fix the fingers at the given opening: weld-like by locking their joints in IK (bounds).
    world = plant.world_body()
    added = []
    for name, X_WB, size in obstacles:
        instance = plant.AddModelInstance(f"obstacle_{name}")
        body = plant.AddRigidBody(f"obstacle_{name}", instance,
                                  SpatialInertia.SolidBoxWithMass(1.0, *size))
        plant.RegisterCollisionGeometry(body, RigidTransform(), Box(*size), f"obstacle_{name}",
                                        CoulombFriction(0.5, 0.5))
        plant.WeldFrames(world.body_frame(), body.body_frame(), X_WB)
        added.append((name, X_WB, size))
    plant.Finalize()
    # The gripper's own bodies never collide with each other or with link 7 (they are attached).
    wsg = plant.GetModelInstanceByName("wsg")
    iiwa = plant.GetModelInstanceByName("iiwa")
    manager = scene_graph.collision_filter_manager()
    gripper_geometries = GeometrySet(
        [g for b in plant.GetBodyIndices(wsg)
         for g in plant.GetCollisionGeometriesForBody(plant.get_body(b))]
        + list(plant.GetCollisionGeometriesForBody(plant.GetBodyByName("iiwa_link_7", iiwa)))
        + list(plant.GetCollisionGeometriesForBody(plant.GetBodyByName("iiwa_link_6", iiwa))))
    manager.Apply(CollisionFilterDeclaration().ExcludeWithin(gripper_geometries))
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    plant_context = plant.GetMyMutableContextFromRoot(context)
    plant.SetPositions(plant_context, wsg, [-finger_opening / 2, finger_opening / 2])
    G = plant.GetFrameByName("body", wsg)
    return ArmPlant(diagram, plant, scene_graph, context, plant_context, G, iiwa, added)


@dataclass
class IkResult:
    success: bool
    q: np.ndarray  # (7,) iiwa joint positions
    position_error: float  # [m] achieved vs requested gripper position
    reason: str = ""


def solve_ik(arm: ArmPlant, X_WG: RigidTransform, *, q_seed=IIWA_HOME,
             position_tolerance: float = 0.002, angle_tolerance: float = 0.02,
             min_distance: float | None = 0.005) -> IkResult:
    """Joint positions putting G at X_WG within tolerances, inside joint limits and (when
    `min_distance` is given) with every collision pair at least that far apart.

    position_tolerance [m] and angle_tolerance [rad] bound the gripper's pose error.
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
    fingers = [plant.GetJointByName(n, wsg).position_start()
               for n in ("left_finger_sliding_joint", "right_finger_sliding_joint")]
    prog = ik.prog()
    for i in fingers:
        prog.AddBoundingBoxConstraint(q_all[i], q_all[i], q[i])
    iiwa_idx = [plant.GetJointByName(f"iiwa_joint_{k + 1}", arm.iiwa).position_start()
                for k in range(7)]
    q_nominal = q_all.copy()
    q_nominal[iiwa_idx] = q_seed
    prog.AddQuadraticErrorCost(np.eye(len(iiwa_idx)) * 0.01, np.asarray(q_seed), q[iiwa_idx])
    prog.SetInitialGuess(q, q_nominal)
    result = Solve(prog)
    q_sol = result.GetSolution(q)
    plant.SetPositions(arm.plant_context, q_sol)
    err = float(np.linalg.norm(arm.G.CalcPoseInWorld(arm.plant_context).translation() - p))
    if not result.is_success():
        return IkResult(False, q_sol[iiwa_idx], err,
                        f"no inverse-kinematics solution ({result.get_solver_id().name()})")
    return IkResult(True, q_sol[iiwa_idx], err)
