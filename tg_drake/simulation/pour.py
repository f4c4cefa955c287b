"""Scripted pours, with no perception or reasoning: the contents' physics on its own.

- `tilt_rig`: a container welded to a link on a PD-driven revolute joint above the table, with
  its spheres (the conservation tests, and the measurement of the contents' settings);
- `scripted_pour`: the station's robot takes a full container by its side (the scripted
  grasp-and-lift of tg_drake.simulation.scripted), lifts it and turns its wrist (iiwa joint 7, the
  gripper's approach axis), tilting the container sideways; `tg-drake bench`'s `pour_run_ratio`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.plant import AddMultibodyPlant
from pydrake.multibody.tree import (
    FixedOffsetFrame,
    PdControllerGains,
    RevoluteJoint,
    SpatialInertia,
)
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from tg_drake.bench import Figure
from tg_drake.models import make_parser
from tg_drake.objects import WATER_DENSITY, get_object, mesh
from tg_drake.robot import WSG_MAX_OPENING
from tg_drake.scenario import ObjectPlacement, Scenario, default_plant_config
from tg_drake.simulation.scripted import drive_station, side_grasp_configurations
from tg_drake.simulation.sleep import ContentsSleep, advance
from tg_drake.station import add_contents_wall, add_spheres, spheres_touch_walls
from tg_drake.table import TABLE_SIZE, X_WT_DEFAULT, add_table
from tg_drake.tasks.contents import ContentsConfig, ContentsModel, container_sites, count_contents

RIG_KP = 200.0  # [N·m/rad] PD gains of the rig's joint
RIG_KD = 20.0  # [N·m·s/rad]
RIG_TORQUE = 200.0  # [N·m] effort limit of the rig's joint


@dataclass
class Rig:
    diagram: object
    plant: object
    body: object  # the container's body
    model: ContentsModel

    def counts(self, context) -> dict[str, int]:
        plant_context = self.plant.GetMyContextFromRoot(context)
        poses = self.plant.get_body_poses_output_port().Eval(plant_context)
        X_WO = self.plant.EvalBodyPoseInWorld(plant_context, self.body)
        return count_contents(self.model, poses, table_z=0.0, containers={
            self.model.name: (X_WO, get_object(self.model.name))})


def tilt_rig(obj_id: str, config: ContentsConfig, *, pivot_height: float = 0.25,
             turn: float = np.pi, duration: float = 1.0, plant_config=None) -> Rig:
    """The table, the container welded to a link on a revolute joint about the world x axis
    through a point `pivot_height` [m] above the table's centre (the container's base 5 cm below
    it), and its spheres; the joint follows a ramp from 0 to `turn` [rad] over `duration` [s]
    through the plant's PD control. Gravity is off for the link and the container (held as a
    robot would hold it), on for the spheres."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(plant_config or default_plant_config(), builder)
    add_table(plant, TABLE_SIZE, X_WT_DEFAULT)
    obj = get_object(obj_id)
    (instance,) = make_parser(plant).AddModels(url=obj.sdf_url)
    body = plant.get_body(plant.GetBodyIndices(instance)[0])
    link = plant.AddRigidBody("rig_link", instance, SpatialInertia.SolidBoxWithMass(
        1.0, 0.05, 0.05, 0.05))
    X_WP = RigidTransform(X_WT_DEFAULT.translation() + [0.0, 0.0, pivot_height])
    pivot = plant.AddFrame(FixedOffsetFrame("rig_pivot", plant.world_frame(), X_WP))
    joint = plant.AddJoint(RevoluteJoint("rig_joint", pivot, link.body_frame(), [1.0, 0.0, 0.0]))
    X_LO = RigidTransform([0.0, 0.0, -0.05])
    plant.WeldFrames(link.body_frame(), body.body_frame(), X_LO)
    actuator = plant.AddJointActuator("rig_actuator", joint, RIG_TORQUE)
    actuator.set_controller_gains(PdControllerGains(p=RIG_KP, d=RIG_KD))
    plant.set_gravity_enabled(instance, False)
    V, F = mesh(obj)[:2]
    p_O = container_sites(obj.id, V, F, config)
    p_W = p_O + (X_WP @ X_LO).translation()
    bodies = add_spheres(plant, plant.AddModelInstance("spheres"), "sphere", p_W, config.radius,
                         WATER_DENSITY * obj.cavity_volume / len(p_O), config)
    walls = add_contents_wall(plant, scene_graph, body, obj)
    plant.Finalize()
    model = ContentsModel(obj.id, bodies, config.radius)
    spheres_touch_walls(plant, scene_graph, [model], walls)
    ramp = PiecewisePolynomial.FirstOrderHold([0.0, duration, duration + 1e3],
                                              [[0.0, turn, turn]])
    source = builder.AddSystem(TrajectorySource(ramp, output_derivative_order=1))
    builder.Connect(source.get_output_port(), plant.get_desired_state_input_port(instance))
    return Rig(builder.Build(), plant, body, model)


@dataclass
class PourResult:
    counts: dict  # where the spheres are at the end (empty for the mass model)
    held: bool  # the container ended above its start height (still in the hand)
    sim_time: float  # [s] simulated
    wall_time: float  # [s] building and simulating


def scripted_pour(scenario: Scenario, *, object_name: str, p_W_grasp, tilt: float,
                  lift: float = 0.15, pitch: float = np.deg2rad(30)) -> PourResult:
    """The scripted side grasp of `object_name` at world point `p_W_grasp`, a lift of `lift`
    [m], then a turn of the wrist (iiwa joint 7) by `tilt` [rad] over 1.5 s, held 1.5 s."""
    t0 = time.perf_counter()
    qs = side_grasp_configurations(scenario, p_W_grasp, lift=lift, pitch=pitch)
    q_tilt = qs[3].copy()
    q_tilt[6] += tilt
    # Timeline [s]: approach, move in, close, lift, tilt, hold.
    times = [0.0, 2.0, 3.0, 4.0, 5.5, 7.0, 8.5]
    driven = drive_station(
        scenario, q_times=times,
        q_knots=np.column_stack([qs[0], qs[1], qs[2], qs[2], qs[3], q_tilt, q_tilt]),
        w_times=[0.0, 3.0, 3.8, times[-1]],
        w_values=[WSG_MAX_OPENING, WSG_MAX_OPENING, 0.0, 0.0])
    station, simulator, plant_context = driven.station, driven.simulator, driven.plant_context
    plant = station.plant
    body = station.object_body(object_name)
    z0 = body.EvalPoseInWorld(plant_context).translation()[2]
    advance(simulator, times[-1], ContentsSleep.for_station(station, scenario.contents))
    wall = time.perf_counter() - t0
    X_WO = body.EvalPoseInWorld(plant_context)
    poses = plant.get_body_poses_output_port().Eval(plant_context)
    placement = next(p for p in scenario.objects if p.instance_name == object_name)
    counts = {}
    for model in station.contents:
        counts = count_contents(model, poses, table_z=0.0, containers={
            object_name: (X_WO, get_object(placement.id))})
    held = bool(X_WO.translation()[2] > z0 + 0.5 * lift)
    return PourResult(counts, held, times[-1], wall)


POUR_OBJECT = "cup_01"
POUR_TILT = np.deg2rad(170.0)  # [rad] of the wrist (iiwa joint 7 turns at most ±175°)


def _pour_scenario(model: str) -> Scenario:
    scenario = Scenario()
    scenario.cameras = {}
    scenario.objects = [ObjectPlacement(id=POUR_OBJECT, pose="upright", containment="full")]
    scenario.contents = ContentsConfig(model=model)
    return scenario


def bench_pour_run_ratio():
    """`pour_run_ratio`: wall seconds (build and simulation) of the scripted pour of a full cup
    whose contents are spheres (grasp, lift, a 170° turn of the wrist, hold: 8.5 s simulated) over
    the same scripted run with the "mass" contents and no turn (a plain pick-and-lift of the same
    object), median of 3 each. Issue 21's goal: ≤ 3."""
    p = [X_WT_DEFAULT.translation()[0], 0.0, 0.5 * get_object(POUR_OBJECT).extents[2]]

    def seconds(model: str, tilt: float) -> float:
        return scripted_pour(_pour_scenario(model), object_name=POUR_OBJECT, p_W_grasp=p,
                             tilt=tilt).wall_time

    pour = sorted(seconds("spheres", POUR_TILT) for _ in range(3))[1]
    plain = sorted(seconds("mass", 0.0) for _ in range(3))[1]
    return Figure(median=pour / plain, unit="ratio (pour run s / pick-and-lift run s)",
                  reference="the same scripted run with the mass contents and no tilt [s]",
                  reference_median=plain, speedup=plain / pour)

