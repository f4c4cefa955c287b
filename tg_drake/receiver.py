"""The receiver of a pass: a second WSG 50, on a kinematic mount, in the station.

    if receiver_of(scenario) is not None:
        instance = add_receiver(plant, parser, scenario)   # before Finalize
        connect_receiver(builder, station)                 # after it: ports receiver.*

Our WSG model (models/wsg_50) parsed again as the model instance "receiver", its body on six
joints from the world — prismatic along the world's x, y, z, then revolute about z, y, x
(`tg_drake.planning.handover.mount_pose`: X_WR = translation · Rz(yaw) · Ry(pitch) · Rx(roll)) —
each driven by the plant's own PD controller like the station's other actuators (implicit in
SAP), gravity off for the instance (compensated, as the robot's gripper). Its fingers are driven
like the robot's WSG: the scenario's `model_drivers.wsg` gains, force limit and coupling
(`WsgPdDriver`).
It starts where it waits (`Handover.X_WR_wait`), fingers open.

Station ports it adds: inputs ``receiver.mount`` (12: the mount's desired q, v), and
``receiver.position`` (1: opening width [m]); output ``receiver.state`` (4: finger q, v, as
``wsg.state``).

`ReceiverDriver` commands it from the planner's ``plan_status``: the plan's `Plan.handover`
(`HandoverMotion`) in plan time once a plan exists, else where it waits, open.

The station has a receiver when the scenario's task is pass or it gives a `receiver` block.
"""

from __future__ import annotations

import numpy as np
import open3d as o3d
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.parsing import (
    AddModel,
    ModelDirective,
    ModelDirectives,
    ProcessModelDirectives,
)
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import (
    JointActuatorIndex,
    ModelInstanceIndex,
    PdControllerGains,
    PrismaticJoint,
    RevoluteJoint,
    SpatialInertia,
)
from pydrake.systems.framework import BasicVector, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import MatrixGain
from scipy.spatial import cKDTree

from tg_drake.planning.handover import (
    Handover,
    ReceiverConfig,
    mount_configuration,
    mount_pose,
)
from tg_drake.robot import WSG_BODY, WSG_FINGER_JOINTS, WSG_MAX_OPENING, WSG_OPEN_POSITIONS
from tg_drake.robot_plants import couple_fingers
from tg_drake.scenario import WsgPdDriver
from tg_drake.systems.plan_messages import PlanState, PlanStatus

RECEIVER = "receiver"  # its model instance's name
MOUNT_JOINTS = ("x", "y", "z", "yaw", "pitch", "roll")  # receiver_<name>, in chain order
MOUNT_LINK_MASS = 0.1  # [kg] each of the mount's five links between its joints (no geometry; a
MOUNT_LINK_RADIUS = 0.02  # [m] small solid sphere each, so that the mass matrix is regular)


def receiver_of(scenario) -> ReceiverConfig | None:
    """The scenario's receiver: its `receiver` block, the default one when the task is pass
    without it, None otherwise."""
    if scenario.receiver is not None:
        return scenario.receiver
    return ReceiverConfig() if scenario.task.task == "pass" else None


def handover_of(scenario) -> Handover | None:
    config = receiver_of(scenario)
    if config is None:
        return None
    return Handover(config, scenario.X_WT.GetDeterministicValue().GetAsMatrix4())


def add_receiver(plant: MultibodyPlant, parser, scenario) -> ModelInstanceIndex:
    """The receiver WSG and its mount, before Finalize (module doc)."""
    handover = handover_of(scenario)
    config = handover.config
    added = ProcessModelDirectives(ModelDirectives(directives=[ModelDirective(add_model=AddModel(
        name=RECEIVER, file="package://tg_drake_models/wsg_50/wsg_50.urdf",
        default_joint_positions={n: [q] for n, q in zip(WSG_FINGER_JOINTS, WSG_OPEN_POSITIONS,
                                                        strict=True)}))]), parser)
    instance = added[0].model_instance
    M = SpatialInertia.SolidSphereWithMass(MOUNT_LINK_MASS, MOUNT_LINK_RADIUS)
    links = [plant.world_body()] + [plant.AddRigidBody(f"{RECEIVER}_mount_{n}", instance, M)
                                    for n in MOUNT_JOINTS[:-1]]
    links.append(plant.GetBodyByName(WSG_BODY, instance))
    q0 = mount_configuration(handover.X_WR_wait)
    axes = ([1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [0, 0, 1.0], [0, 1.0, 0], [1.0, 0, 0])
    for k, (name, axis) in enumerate(zip(MOUNT_JOINTS, axes, strict=True)):
        parent, child = links[k].body_frame(), links[k + 1].body_frame()
        if k < 3:
            joint = plant.AddJoint(PrismaticJoint(f"{RECEIVER}_{name}", parent, child, axis))
            joint.set_default_translation(float(q0[k]))
            gains = PdControllerGains(p=config.kp, d=config.kd)
        else:
            joint = plant.AddJoint(RevoluteJoint(f"{RECEIVER}_{name}", parent, child, axis))
            joint.set_default_angle(float(q0[k]))
            gains = PdControllerGains(p=config.kp_rotation, d=config.kd_rotation)
        actuator = plant.AddJointActuator(f"{RECEIVER}_{name}", joint, config.force_limit)
        actuator.set_controller_gains(gains)
    # The fingers as the robot's WSG.
    driver = scenario.model_drivers.get("wsg")
    driver = driver if isinstance(driver, WsgPdDriver) else WsgPdDriver()
    for name in WSG_FINGER_JOINTS:
        actuator = plant.GetJointActuatorByName(name, instance)
        actuator.set_controller_gains(PdControllerGains(p=driver.kp, d=driver.kd))
        actuator.set_effort_limit(driver.force_limit)
    if driver.coupled:
        couple_fingers(plant, instance)
    plant.set_gravity_enabled(instance, False)
    return instance


class ReceiverCommand(LeafSystem):
    """``mount`` (12: desired q, v of the six mount joints, in MOUNT_JOINTS order) and
    ``position`` (1: opening width [m]) → the receiver instance's desired state, in the order of
    its actuators."""

    def __init__(self, order: list[tuple[str, int]]):
        """`order`: per actuator of the instance (its desired-state order) ("mount", k) or
        ("finger", ±1)."""
        super().__init__()
        self._order = list(order)
        self._mount = self.DeclareVectorInputPort("mount", 12)
        self._width = self.DeclareVectorInputPort("position", 1)
        self.DeclareVectorOutputPort("desired_state", 2 * len(order), self._calc)

    def _calc(self, context, output):
        mount = self._mount.Eval(context)
        w = self._width.Eval(context)[0]
        n = len(self._order)
        x = np.zeros(2 * n)
        for i, (kind, k) in enumerate(self._order):
            if kind == "mount":
                x[i], x[n + i] = mount[k], mount[6 + k]
            else:
                x[i] = k * w / 2
        output.SetFromVector(x)


def connect_receiver(builder: DiagramBuilder, station) -> None:
    """After Finalize: the receiver's command system and its station ports (module doc)."""
    plant = station.plant
    instance = station.instances[RECEIVER]
    actuators = [plant.get_joint_actuator(JointActuatorIndex(i))
                 for i in range(plant.num_actuators())]
    order = []
    for a in actuators:
        if a.model_instance() != instance:
            continue
        name = a.joint().name()
        if name in WSG_FINGER_JOINTS:
            order.append(("finger", -1 if name == WSG_FINGER_JOINTS[0] else 1))
        else:
            order.append(("mount", MOUNT_JOINTS.index(name.removeprefix(f"{RECEIVER}_"))))
    command = builder.AddNamedSystem("receiver_command", ReceiverCommand(order))
    builder.Connect(command.get_output_port(), plant.get_desired_state_input_port(instance))
    station.inputs["receiver.mount"] = command.GetInputPort("mount")
    station.inputs["receiver.position"] = command.GetInputPort("position")
    # The fingers' state (q, v), as wsg.state: the instance's state is the mount's then the
    # fingers' positions and velocities in the plant's order; pick the fingers'.
    station.outputs["receiver.state"] = _finger_state(builder, plant, instance).get_output_port()


def _finger_state(builder, plant, instance):
    n_q, n_v = plant.num_positions(instance), plant.num_velocities(instance)
    S = np.zeros((4, n_q + n_v))
    for row, name in enumerate(WSG_FINGER_JOINTS):
        joint = plant.GetJointByName(name, instance)
        q0 = joint.position_start() - _first_position(plant, instance)
        v0 = joint.velocity_start() - _first_velocity(plant, instance)
        S[row, q0] = 1.0
        S[2 + row, n_q + v0] = 1.0
    gain = builder.AddNamedSystem("receiver_finger_state", MatrixGain(S))
    builder.Connect(plant.get_state_output_port(instance), gain.get_input_port())
    return gain


def _first_position(plant, instance) -> int:
    return min(plant.get_joint(j).position_start() for j in plant.GetJointIndices(instance)
               if plant.get_joint(j).num_positions() > 0)


def _first_velocity(plant, instance) -> int:
    return min(plant.get_joint(j).velocity_start() for j in plant.GetJointIndices(instance)
               if plant.get_joint(j).num_velocities() > 0)


# [m] how far apart the receiver matches a point of the object's surface where the plan carries
# it to the surface where it is, when it looks for the smallest move that shows the same shape
# (`seen_correction`): a few times the tolerance, under the drifts it must follow by the frame.
SEE_MATCH_DISTANCE = 0.02


class Surface:
    """An object's surface for `seen_correction`: points p_O and outward normals n_O (n, 3) in its
    frame, and what matching against it needs, made once (Open3D's cloud, a k-d tree)."""

    def __init__(self, p_O: np.ndarray, n_O: np.ndarray):
        self.p_O, self.n_O = np.asarray(p_O, float), np.asarray(n_O, float)
        self.cloud = o3d.geometry.PointCloud()
        self.cloud.points = o3d.utility.Vector3dVector(self.p_O)
        self.cloud.normals = o3d.utility.Vector3dVector(self.n_O)
        self.tree = cKDTree(self.p_O)


def seen_correction(C: np.ndarray, X_expected: np.ndarray, surface: Surface,
                    tolerance: float) -> np.ndarray:
    """The move (4×4, world) the receiver follows, given the object's true move C (X_WO ·
    X_expected⁻¹) from where the plan carries it (X_expected) and its `surface`: the smallest
    move that shows the same shape — an ICP (Open3D, point to plane, from no move) of the surface
    where it is expected onto where it is — when it matches within `tolerance` [m] (95th
    percentile of the point-to-plane distances), else C. (Matched in the frame of the object
    where it is, against the surface as made once: the same move.) A person sees the shape, not
    the frame: a glass rolled about its axis in the robot's hand looks as it did, and following
    the frame's roll would swing the receiver's way in about the object (into the robot's arm);
    a cup turned so is followed by its handle."""
    X_expected, C = np.asarray(X_expected, float), np.asarray(C, float)
    X_actual = C @ X_expected
    A = np.linalg.inv(X_actual) @ X_expected  # where it is expected, seen from where it is
    source = surface.p_O @ A[:3, :3].T + A[:3, 3]
    src = o3d.geometry.PointCloud()
    src.points = o3d.utility.Vector3dVector(source)
    reg = o3d.pipelines.registration
    T = np.asarray(reg.registration_icp(
        src, surface.cloud, SEE_MATCH_DISTANCE, np.eye(4),
        reg.TransformationEstimationPointToPlane(),
        reg.ICPConvergenceCriteria(max_iteration=30)).transformation)
    moved = source @ T[:3, :3].T + T[:3, 3]
    _, i = surface.tree.query(moved)
    gap = np.abs(np.einsum("ij,ij->i", moved - surface.p_O[i], surface.n_O[i]))
    if np.percentile(gap, 95) > tolerance:
        return C
    return X_actual @ T @ np.linalg.inv(X_actual)


class ReceiverDriver(LeafSystem):
    """Commands the receiver from the planner's ``plan_status``: the plan's hand-over motion
    (`Plan.handover`) in plan time, else where it waits with its fingers open.

    .. pydrake_system::

        name: ReceiverDriver
        input_ports:
        - plan_status
        - body_poses (optional)
        output_ports:
        - receiver.mount
        - receiver.position

    The receiver stands for the person who takes the object, and like a person it sees where the
    object is: with ``body_poses`` connected, every `period` seconds from the robot's arrival at
    the hand-over pose (`HandoverMotion.t_arrive`) until its pads begin to close (the end of its
    straight approach: a heavy tool still turning slowly in the robot's grip is followed as the
    receiver reaches for it), it compares the object's simulated pose with where the plan carries
    it (rigidly from where it stood, with the robot's gripper: `HandoverMotion.X_WG_robot` ·
    `Plan.X_WG_grasp`⁻¹ · the pose at the plan's start) and moves its motion from then on with the
    difference (an object that shifted in the robot's hand as the pads closed); then the
    correction is kept. Given the object's `surface` (`Surface`: points and outward normals in
    its frame), it follows the smallest move that shows the same shape instead
    (`seen_correction`). The robot's pipeline never sees it.
    """

    def __init__(self, handover: Handover, *, object_body: int | None = None,
                 period: float = 0.05, surface: Surface | None = None):
        super().__init__()
        self._q_wait = mount_configuration(handover.X_WR_wait)
        self._object = object_body
        self._surface = surface
        self._see = handover.config.see_tolerance
        self._status = self.DeclareAbstractInputPort(
            "plan_status", AbstractValue.Make(PlanStatus(PlanState.planning)))
        self._poses = self.DeclareAbstractInputPort(
            "body_poses", AbstractValue.Make([RigidTransform()]))
        # (X_WO at the plan's start or None, the correction C (4×4) applied to the motion)
        self.DeclareAbstractState(AbstractValue.Make((None, np.eye(4))))  # the only state
        self.DeclarePeriodicUnrestrictedUpdateEvent(period, 0.0, self._look)
        on = {self.all_input_ports_ticket(), self.all_state_ticket(), self.time_ticket()}
        self.DeclareVectorOutputPort("receiver.mount", 12, self._calc_mount,
                                     prerequisites_of_calc=on)
        self.DeclareVectorOutputPort("receiver.position", 1, self._calc_width,
                                     prerequisites_of_calc=on)

    def _look(self, context, state):
        if self._object is None or not self._poses.HasValue(context):
            return
        motion, t = self._motion(context)
        X_start, C = context.get_abstract_state(0).get_value()
        if motion is None or t >= motion.times[4]:  # no plan yet, or closing: keep
            return
        if X_start is not None and t < motion.t_arrive:  # carrying: nothing to compare yet
            return
        X_WO = self._poses.Eval(context)[self._object].GetAsMatrix4()
        plan = self._status.Eval(context).plan
        if X_start is None:  # standing where perception saw it
            state.get_mutable_abstract_state(0).set_value((X_WO, C))
            return
        expected = motion.X_WG_robot @ np.linalg.inv(np.asarray(plan.X_WG_grasp)) @ X_start
        C = X_WO @ np.linalg.inv(expected)
        if self._surface is not None:
            C = seen_correction(C, expected, self._surface, self._see)
        state.get_mutable_abstract_state(0).set_value((X_start, C))

    def _motion(self, context):
        status: PlanStatus = self._status.Eval(context)
        plan = status.plan
        motion = getattr(plan, "handover", None) if plan is not None else None
        if motion is None or status.t_plan is None:
            return None, 0.0
        return motion, context.get_time() - status.t_plan

    def _calc_mount(self, context, output: BasicVector):
        motion, t = self._motion(context)
        if motion is None:
            output.SetFromVector(np.concatenate([self._q_wait, np.zeros(6)]))
            return
        q, v = motion.configuration(t), motion.velocity(t)
        C = context.get_abstract_state(0).get_value()[1]
        if t >= motion.t_arrive and not np.allclose(C, np.eye(4)):  # at the hand-over
            q = mount_configuration(C @ mount_pose(q), near=q)
        output.SetFromVector(np.concatenate([q, v]))

    def _calc_width(self, context, output: BasicVector):
        motion, t = self._motion(context)
        output.SetAtIndex(0, WSG_MAX_OPENING if motion is None else motion.width(t))


def receiver_pose(plant, plant_context) -> RigidTransform:
    """X_WR: the receiver's WSG body frame."""
    return plant.GetFrameByName(WSG_BODY, plant.GetModelInstanceByName(RECEIVER)
                                ).CalcPoseInWorld(plant_context)
