"""A scripted grasp-and-lift in the station, with no perception or reasoning.

Used by the station tests (does the WSG hold a can / a cup body?) and by `tg-drake bench` for the
`sim_rtf` figure. The gripper approaches the object's side from the robot's side, tilted 30° down,
closes across the object at a chosen height, and the arm lifts it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.plant import ContactResults
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from tg_drake.bench import Figure
from tg_drake.errors import PlanningError, SimulationError
from tg_drake.grasping.pads import GRASP_DEPTH  # [m] the grasp point along +y_G
from tg_drake.objects import get_object
from tg_drake.outcome import HandGeometries, hand_contact
from tg_drake.planning.ik import make_arm_plant, solve_ik
from tg_drake.robot import IIWA_HOME, WSG_BODY, WSG_MAX_OPENING
from tg_drake.scenario import InverseDynamicsDriver, ObjectPlacement, Scenario
from tg_drake.station import add_station, rotation_from_axes


@dataclass
class GraspLiftResult:
    held: bool  # the object rose with the gripper and the fingers did not close on air
    object_rise: float  # [m] object height change between grasp and end of lift
    gripper_rise: float  # [m] gripper height change over the same interval
    finger_opening: float  # [m] at the end
    hydroelastic_surfaces: int  # contact surfaces touching the object at the end
    sim_time: float  # [s] simulated
    wall_time: float  # [s] of AdvanceTo, excluding building
    render_time: float  # [s] rendering the camera frame at the start


def side_grasp_pose(p_WO_center, approach_W=(1.0, 0.0, 0.0), *, pitch: float = 0.0
                    ) -> RigidTransform:
    """X_WG for a side grasp whose grasp point is at `p_WO_center`: the fingers close horizontally;
    the approach is `approach_W` projected on the horizontal and tilted `pitch` [rad] downwards
    (a downward tilt keeps the wrist clear of the table for low grasps)."""
    horizontal = np.array([approach_W[0], approach_W[1], 0.0], float)
    horizontal /= np.linalg.norm(horizontal)
    approach = np.cos(pitch) * horizontal + np.array([0.0, 0.0, -np.sin(pitch)])
    closing = np.cross([0.0, 0.0, 1.0], horizontal)  # horizontal, perpendicular to the approach
    R_WG = rotation_from_axes(closing, approach)
    return RigidTransform(R_WG, np.asarray(p_WO_center) - GRASP_DEPTH * approach)


def side_grasp_configurations(scenario: Scenario, p_W_grasp, *, lift: float, pitch: float
                              ) -> list[np.ndarray]:
    """The iiwa configurations of a scripted side grasp at world point `p_W_grasp`, approached
    horizontally from the robot's side: [home, pre-grasp (10 cm back), grasp, lift (`lift` [m]
    up)], by IK on a kinematic arm model, each seeded by the one before; PlanningError naming
    the pose that is out of reach."""
    p = np.asarray(p_W_grasp, float)
    X_grasp = side_grasp_pose(p, np.array([p[0], p[1], 0.0]), pitch=pitch)
    y_G = X_grasp.rotation().col(1)
    X_pre = RigidTransform(X_grasp.rotation(), X_grasp.translation() - 0.10 * y_G)
    X_lift = RigidTransform(X_grasp.rotation(), X_grasp.translation() + [0, 0, lift])
    arm = make_arm_plant(scenario)
    qs = [np.asarray(IIWA_HOME)]
    for name, X, min_distance in (("pre-grasp", X_pre, 0.005), ("grasp", X_grasp, None),
                                  ("lift", X_lift, None)):
        r = solve_ik(arm, X, q_seed=qs[-1], min_distance=min_distance)
        if not r.success:
            raise PlanningError(f"{name} pose unreachable: {r.reason}")
        qs.append(r.q)
    return qs


@dataclass
class DrivenStation:
    """A station whose arm and gripper follow fixed trajectories (`drive_station`)."""

    station: object  # tg_drake.station.Station
    simulator: Simulator
    plant_context: object  # the plant's mutable context inside the simulator's


def drive_station(scenario: Scenario, *, q_times, q_knots, w_times, w_values) -> DrivenStation:
    """The scenario's station with its iiwa following the first-order hold through `q_knots`
    ((7, K) joint positions [rad] at `q_times` [s], with their derivative as the desired velocity)
    and its WSG the opening `w_values` [m] at `w_times` [s]; the arm starts at the first knot."""
    builder = DiagramBuilder()
    station = add_station(builder, scenario=scenario)
    q_traj = PiecewisePolynomial.FirstOrderHold(list(q_times), np.asarray(q_knots, float))
    w_traj = PiecewisePolynomial.FirstOrderHold(list(w_times), np.atleast_2d(w_values))
    arm_source = builder.AddSystem(TrajectorySource(q_traj, output_derivative_order=1))
    wsg_source = builder.AddSystem(TrajectorySource(w_traj))
    builder.Connect(arm_source.get_output_port(), station.inputs["iiwa.desired_state"])
    builder.Connect(wsg_source.get_output_port(), station.inputs["wsg.position"])
    simulator = Simulator(builder.Build())
    plant_context = station.plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    station.plant.SetPositions(plant_context, station.instances["iiwa"],
                               np.asarray(q_knots, float)[:, 0])
    return DrivenStation(station, simulator, plant_context)


def grasp_and_lift(scenario: Scenario, *, object_name: str, p_W_grasp, lift: float = 0.10,
                   pitch: float = np.deg2rad(30), render: bool = True,
                   width_closed: float = 0.0) -> GraspLiftResult:
    """Runs the scripted grasp-and-lift on `object_name`, grasping at world point `p_W_grasp`."""
    qs = side_grasp_configurations(scenario, p_W_grasp, lift=lift, pitch=pitch)
    # Timeline [s]: approach, move in, close, lift, hold.
    times = [0.0, 2.0, 3.0, 4.0, 5.5, 6.5]
    w_open = WSG_MAX_OPENING
    driven = drive_station(scenario, q_times=times,
                           q_knots=np.column_stack([qs[0], qs[1], qs[2], qs[2], qs[3], qs[3]]),
                           w_times=[0.0, 3.0, 3.8, times[-1]],
                           w_values=[w_open, w_open, width_closed, width_closed])
    station, simulator, plant_context = driven.station, driven.simulator, driven.plant_context
    plant, context = station.plant, simulator.get_mutable_context()
    body = station.object_body(object_name)
    G = plant.GetFrameByName(WSG_BODY, station.instances["wsg"])

    render_time = 0.0
    if render and station.cameras:
        sensor = next(iter(station.cameras.values())).sensor
        t0 = time.perf_counter()
        sensor.depth_image_32F_output_port().Eval(sensor.GetMyContextFromRoot(context))
        render_time = time.perf_counter() - t0

    simulator.Initialize()
    t0 = time.perf_counter()
    simulator.AdvanceTo(times[3])
    z_obj_grasp = body.EvalPoseInWorld(plant_context).translation()[2]
    z_g_grasp = G.CalcPoseInWorld(plant_context).translation()[2]
    simulator.AdvanceTo(times[-1])
    wall = time.perf_counter() - t0

    X_WO = body.EvalPoseInWorld(plant_context)
    if not np.all(np.isfinite(X_WO.GetAsMatrix4())):
        raise SimulationError("the simulation diverged (non-finite object pose)")
    q_wsg = plant.GetPositions(plant_context, station.instances["wsg"])
    contact: ContactResults = plant.get_contact_results_output_port().Eval(plant_context)
    hand = hand_contact(contact, wsg_q=q_wsg[:2], R_WG=G.CalcPoseInWorld(plant_context).rotation(),
                        geometries=HandGeometries.from_plant(
                            plant, object_body=body, wsg_instance=station.instances["wsg"],
                            table_instance=station.instances["table"]))
    opening, surfaces = hand.opening, hand.hydroelastic
    object_rise = X_WO.translation()[2] - z_obj_grasp
    gripper_rise = G.CalcPoseInWorld(plant_context).translation()[2] - z_g_grasp
    held = bool(object_rise > 0.8 * gripper_rise and hand.held)
    return GraspLiftResult(held, float(object_rise), float(gripper_rise), opening, surfaces,
                           times[-1], wall, render_time)


def bench_sim_rtf():
    """`sim_rtf`: simulated seconds per wall second of the scripted grasp-and-lift of a full can
    (6.5 s simulated), one camera frame rendered at its start. The reference is the same run with
    Drake's explicit inverse-dynamics arm controller at a 2 ms step; `speedup` = ours / reference
    (a rate: higher is better)."""
    def run(explicit: bool) -> float:
        scenario = Scenario()
        scenario.objects = [ObjectPlacement(id="can_02", pose="upright", yaw=90,
                                            containment="full")]
        if explicit:
            scenario.model_drivers["iiwa"] = InverseDynamicsDriver()
            scenario.plant_config.time_step = 0.002
        height = get_object("can_02").extents[2]
        r = grasp_and_lift(scenario, object_name="can_02", p_W_grasp=[0.75, 0.0, 0.5 * height])
        return r.sim_time / (r.wall_time + r.render_time)

    ours = sorted(run(False) for _ in range(3))[1]
    reference = sorted(run(True) for _ in range(3))[1]
    return Figure(median=ours, unit="simulated s / wall s",
                  reference="explicit InverseDynamicsController, 2 ms step, same grasp-and-lift",
                  reference_median=reference, speedup=ours / reference)
