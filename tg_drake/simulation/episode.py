"""One grasp, executed in physics: a free-floating WSG 50 approaches, closes, lifts and shakes.

This module labels training data for the DGI classifier (tools/collect_grasps.py). It builds and
simulates a Drake diagram, so it lives beside the station, not in the grasping core (dgi.py,
svm.py, hypotheses.py), which never imports it.

The world: the table (tg_drake.table, its default size) with its top at z_W = 0, one object
resting on it, and the WSG 50 of models/wsg_50/wsg_50.urdf carried by six actuated joints — three
prismatic and three revolute — on a frame F welded to the world at the grasp pose X_WG. The
joints therefore measure the gripper's displacement from the grasp pose, expressed in the grasp
frame, and are zero at the grasp; no parametrisation singularity occurs for any grasp
orientation. Every joint is PD-controlled through its JointActuator gains with the desired state
on the plant's `desired_state` input port (implicit in SAP); gravity is off for the gripper's
bodies, which stand in for an arm that compensates it.

An episode (all times in seconds, `EpisodeConfig`):

1. approach: from `approach_distance` back along −y_G to the grasp pose, fingers fully open;
2. close: the finger set points move past the centre, so each pad presses with up to
   `grip_force` [N] (the drive's effort limit caps it at 80 N);
3. lift: the gripper rises `lift_height` along +z_W;
4. shake: a horizontal circle of radius `shake_amplitude` and a rotation about z_G (across the
   pads), `shake_cycles` times, under a sin² envelope so that it starts and stops at rest.

Label: success when at the end the object is held between the fingers — the run's one rule for
"held", `tg_drake.outcome.is_held`: it pushes both pads apart — the fingers stand closer than the
full opening less `min_finger_travel` on each side (fingers that never moved cannot hold anything,
even if pressing their tips on a face carried the object up), and the object no longer touches the
table. A run whose physics fails (solver error, NaN, the
object falling through the table or flying off) is reported with status "sim_error" and its reason
instead of a label.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from importlib.resources import files

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlantConfig
from pydrake.multibody.tree import (
    FixedOffsetFrame,
    PdControllerGains,
    PrismaticJoint,
    RevoluteJoint,
    SpatialInertia,
    UnitInertia,
)
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import BasicVector, DiagramBuilder, LeafSystem

from tg_drake.errors import SimulationError
from tg_drake.grasping.dgi import MAX_OPENING
from tg_drake.outcome import HandGeometries, hand_contact, touches_table
from tg_drake.robot import WSG_BODY, WSG_FINGER_JOINTS
from tg_drake.robot_plants import couple_fingers
from tg_drake.table import TABLE_SIZE, add_table

TABLE_TOP_Z = 0.0  # the table's top surface in the world [m] (table_top frame welded at W).
FINGER_JOINTS = WSG_FINGER_JOINTS
CARRIER_JOINTS = ("carrier_x", "carrier_y", "carrier_z", "carrier_rx", "carrier_ry", "carrier_rz")


@dataclass
class EpisodeConfig:
    """The physics and the script of one grasp episode."""

    time_step: float = 0.005  # discrete plant step [s] (2–10 ms held a grasp: docs/design.md).
    approach_distance: float = 0.05  # start this far back along −y_G [m].
    approach_time: float = 0.15  # [s]
    close_time: float = 0.3  # [s]
    lift_height: float = 0.10  # [m] along +z_W.
    lift_time: float = 0.3  # [s]
    shake_time: float = 0.3  # [s]
    shake_amplitude: float = 0.015  # radius of the horizontal shake circle [m].
    shake_angle: float = 0.15  # amplitude of the rotation about z_G [rad].
    shake_cycles: float = 1.5  # full periods within shake_time.
    grip_force: float = 60.0  # set-point force of each finger [N] (the effort limit is 80 N).
    finger_kp: float = 2000.0  # finger PD gains [N/m], [N·s/m] (as the station's WSG driver).
    finger_kd: float = 50.0
    coupled: bool = True  # the fingers move as one drive moves them (as the station's WSG:
    # `tg_drake.robot_plants.couple_fingers`)
    carrier_kp_translation: float = 2.0e5  # [N/m]: 0.06 mm sag under a 1.2 kg object's weight.
    carrier_kd_translation: float = 2.0e3  # [N·s/m]: well damped for the 1.1 kg gripper.
    carrier_kp_rotation: float = 2.0e3  # [N·m/rad]
    carrier_kd_rotation: float = 20.0  # [N·m·s/rad]
    carrier_force_limit: float = 150.0  # [N] per translation joint: an arm pushes no harder.
    carrier_torque_limit: float = 15.0  # [N·m] per rotation joint.
    min_finger_travel: float = 0.005  # each finger must have closed at least this much [m].
    object_mass: float = 0.0  # > 0: the object's inertia scaled to this mass [kg] (same shape and
    # centre of mass): labels that do not depend on how heavy the object is.

    @property
    def duration(self) -> float:
        return self.approach_time + self.close_time + self.lift_time + self.shake_time


def _smoothstep(s):
    """Position and derivative of 3s² − 2s³ on [0, 1] (clamped outside)."""
    s = np.clip(s, 0.0, 1.0)
    return 3 * s**2 - 2 * s**3, 6 * s * (1 - s)


def scripted_targets(t: float, config: EpisodeConfig, R_GW: np.ndarray) -> dict:
    """Joint name → (desired position, desired velocity) of the eight actuated joints at time t.

    R_GW expresses the world-frame lift and shake in the grasp frame F = G₀.
    """
    c = config
    # 1. approach along +y_G.
    s, ds = _smoothstep(t / c.approach_time)
    p_G = np.array([0.0, -c.approach_distance * (1 - s), 0.0])
    v_G = np.array([0.0, c.approach_distance * ds / c.approach_time, 0.0])
    # 2. close: from fully open to past the centre by grip_force / kp.
    t_close = t - c.approach_time
    s, ds = _smoothstep(t_close / c.close_time)
    open_q = MAX_OPENING / 2
    closed_q = -c.grip_force / c.finger_kp
    finger_q = open_q + (closed_q - open_q) * s
    finger_v = (closed_q - open_q) * ds / c.close_time
    # 3. lift along +z_W.
    t_lift = t_close - c.close_time
    s, ds = _smoothstep(t_lift / c.lift_time)
    p_W = np.array([0.0, 0.0, c.lift_height * s])
    v_W = np.array([0.0, 0.0, c.lift_height * ds / c.lift_time])
    # 4. shake: a horizontal circle and a rotation about z_G, under a sin² envelope.
    t_shake = t_lift - c.lift_time
    angle = rate = 0.0
    if 0.0 < t_shake < c.shake_time:
        omega = 2 * np.pi * c.shake_cycles / c.shake_time
        env = np.sin(np.pi * t_shake / c.shake_time) ** 2
        denv = np.pi / c.shake_time * np.sin(2 * np.pi * t_shake / c.shake_time)
        ring = np.array([np.sin(omega * t_shake), 1 - np.cos(omega * t_shake), 0.0])
        dring = omega * np.array([np.cos(omega * t_shake), np.sin(omega * t_shake), 0.0])
        p_W += c.shake_amplitude * env * ring
        v_W += c.shake_amplitude * (denv * ring + env * dring)
        angle = c.shake_angle * env * np.sin(omega * t_shake)
        rate = c.shake_angle * (denv * np.sin(omega * t_shake)
                                + env * omega * np.cos(omega * t_shake))
    p_G = p_G + R_GW @ p_W
    v_G = v_G + R_GW @ v_W
    targets = {name: (p_G[axis], v_G[axis]) for axis, name in enumerate(CARRIER_JOINTS[:3])}
    targets.update(carrier_rx=(0.0, 0.0), carrier_ry=(0.0, 0.0), carrier_rz=(angle, rate))
    # The left finger moves along −x (its joint runs from −0.055 open to 0 closed).
    targets[FINGER_JOINTS[0]] = (-finger_q, -finger_v)
    targets[FINGER_JOINTS[1]] = (finger_q, finger_v)
    return targets


class GraspScript(LeafSystem):
    """
    .. pydrake_system::

        name: GraspScript
        output_ports:
        - desired_state

    The desired state of the gripper's eight actuated joints over an episode
    (`scripted_targets`), in the plant's actuator order, given as `actuator_joints`. Numeric
    parameter: R_GW (9 entries, row-major) of the episode's grasp pose.
    """

    def __init__(self, config: EpisodeConfig, actuator_joints: list[str]):
        super().__init__()
        self._config = config
        self._joints = list(actuator_joints)
        self._R_GW_index = self.DeclareNumericParameter(BasicVector(np.eye(3).ravel()))
        self._desired_state = self.DeclareVectorOutputPort(
            "desired_state", 2 * len(self._joints), self._calc_desired_state)

    def get_desired_state_output_port(self):
        return self._desired_state

    def set_grasp_orientation(self, context, R_WG: np.ndarray) -> None:
        context.get_mutable_numeric_parameter(self._R_GW_index).SetFromVector(R_WG.T.ravel())

    def _calc_desired_state(self, context, output):
        R_GW = context.get_numeric_parameter(self._R_GW_index).value().reshape(3, 3)
        targets = scripted_targets(context.get_time(), self._config, R_GW)
        q, v = zip(*(targets[name] for name in self._joints), strict=False)
        output.SetFromVector(np.concatenate([q, v]))


def _carrier_inertia() -> SpatialInertia:
    # 10 g, a 2 cm sphere's inertia: small against the gripper's 1.1 kg, enough to stay well posed.
    return SpatialInertia(0.01, np.zeros(3), UnitInertia.SolidSphere(0.01))


class GraspWorld:
    """A table, one object and a carried WSG 50, built once and reused for many episodes."""

    def __init__(self, object_sdf: str, config: EpisodeConfig | None = None):
        self.config = config = config or EpisodeConfig()
        builder = DiagramBuilder()
        plant, scene_graph = AddMultibodyPlant(
            MultibodyPlantConfig(time_step=config.time_step,
                                 contact_model="hydroelastic_with_fallback",
                                 discrete_contact_approximation="sap"),
            builder)
        parser = Parser(plant)
        # (from its text: a table file would take libsdformat ~25 ms to load at every world)
        table = add_table(plant, TABLE_SIZE, RigidTransform([0.0, 0.0, TABLE_TOP_Z]))
        (wsg,) = parser.AddModels(str(files("tg_drake_models") / "wsg_50" / "wsg_50.urdf"))
        object_models = parser.AddModels(object_sdf)
        bodies = [plant.get_body(i) for m in object_models for i in plant.GetBodyIndices(m)]
        if len(bodies) != 1:
            raise SimulationError(f"the object model must have exactly one body, has {len(bodies)}",
                                  file=str(object_sdf))
        self.object_body = bodies[0]

        # The carrier: F (the grasp frame, set per episode) → x → y → z → rx → ry → rz → G.
        self.grasp_frame = plant.AddFrame(FixedOffsetFrame("grasp_frame", plant.world_frame(),
                                                           RigidTransform()))
        parent = self.grasp_frame
        axes = np.eye(3)
        for k, name in enumerate(CARRIER_JOINTS):
            if k < 5:
                child_body = plant.AddRigidBody(f"{name}_link", wsg, _carrier_inertia())
                child = child_body.body_frame()
            else:
                child = plant.GetFrameByName(WSG_BODY, wsg)
            joint_type = PrismaticJoint if k < 3 else RevoluteJoint
            joint = plant.AddJoint(joint_type(name, parent, child, axes[k % 3]))
            actuator = plant.AddJointActuator(
                name, joint, config.carrier_force_limit if k < 3 else config.carrier_torque_limit)
            kp, kd = ((config.carrier_kp_translation, config.carrier_kd_translation) if k < 3
                      else (config.carrier_kp_rotation, config.carrier_kd_rotation))
            actuator.set_controller_gains(PdControllerGains(p=kp, d=kd))
            parent = child
        for name in FINGER_JOINTS:
            plant.GetJointActuatorByName(name, wsg).set_controller_gains(
                PdControllerGains(p=config.finger_kp, d=config.finger_kd))
        if config.coupled:
            couple_fingers(plant, wsg)
        plant.set_gravity_enabled(wsg, False)
        plant.Finalize()

        actuator_joints = [plant.get_joint_actuator(i).joint().name()
                           for i in plant.GetJointActuatorIndices(wsg)]
        script = builder.AddSystem(GraspScript(config, actuator_joints))
        builder.Connect(script.get_desired_state_output_port(),
                        plant.get_desired_state_input_port(wsg))
        self.diagram = builder.Build()
        self.plant = plant
        self.script = script
        self.wsg = wsg
        self.fingers = [plant.GetJointByName(n, wsg) for n in FINGER_JOINTS]
        self.carrier = [plant.GetJointByName(n, wsg) for n in CARRIER_JOINTS]
        self._hand = HandGeometries.from_plant(plant, object_body=self.object_body,
                                               wsg_instance=wsg, table_instance=table)
        self._gripper_body = plant.GetBodyByName(WSG_BODY, wsg)
        self.simulator = Simulator(self.diagram)
        self.context = self.simulator.get_mutable_context()
        self._default_state = self.context.get_discrete_state_vector().CopyToVector()
        if config.object_mass > 0:
            M = self.object_body.default_spatial_inertia()
            self.object_body.SetSpatialInertiaInBodyFrame(
                plant.GetMyMutableContextFromRoot(self.context),
                SpatialInertia(config.object_mass, M.get_com(), M.get_unit_inertia()))

    def run(self, X_WO: np.ndarray, X_WG: np.ndarray) -> dict:
        """Executes one grasp on the object resting at X_WO with the gripper closing at X_WG.

        Returns a JSON-ready dict: status "ok" with `success` (bool), or "sim_error" with `reason`;
        plus what was measured (finger gap, object rise, wall time).
        """
        c = self.config
        start = time.perf_counter()
        context = self.context
        context.SetTime(0.0)
        context.get_mutable_discrete_state_vector().SetFromVector(self._default_state)
        plant_context = self.plant.GetMyMutableContextFromRoot(context)
        X_WG = RigidTransform(np.asarray(X_WG, dtype=float))
        self.grasp_frame.SetPoseInParentFrame(plant_context, X_WG)
        self.script.set_grasp_orientation(
            self.script.GetMyMutableContextFromRoot(context), X_WG.rotation().matrix())
        self.carrier[1].set_translation(plant_context, -c.approach_distance)
        self.fingers[0].set_translation(plant_context, -MAX_OPENING / 2)
        self.fingers[1].set_translation(plant_context, MAX_OPENING / 2)
        X_WO = RigidTransform(np.asarray(X_WO, dtype=float))
        self.plant.SetFreeBodyPose(plant_context, self.object_body, X_WO)
        z0 = X_WO.translation()[2]
        result = {"status": "ok"}
        phases = (("approach", c.approach_time), ("close", c.close_time),
                  ("lift", c.lift_time), ("shake", c.shake_time))
        try:
            self.simulator.Initialize()
            t = 0.0
            for phase, duration in phases:
                t += duration
                self.simulator.AdvanceTo(t)
                error = self._check(plant_context, z0)
                if error:
                    result = {"status": "sim_error", "reason": f"{error} during {phase}"}
                    break
        except RuntimeError as e:
            result = {"status": "sim_error", "reason": f"{type(e).__name__}: {e}".strip()[:300]}
        if result["status"] == "ok":
            X_WO_end = self.plant.EvalBodyPoseInWorld(plant_context, self.object_body)
            contacts = self.plant.get_contact_results_output_port().Eval(plant_context)
            hand = hand_contact(contacts, wsg_q=[f.get_translation(plant_context)
                                                 for f in self.fingers],
                                geometries=self._hand,
                                R_WG=self._gripper_body.EvalPoseInWorld(plant_context).rotation())
            on_table = touches_table(contacts, geometries=self._hand)
            moved = hand.opening < MAX_OPENING - 2 * c.min_finger_travel
            result.update(
                success=bool(hand.held and moved and not on_table),
                finger_gap=hand.opening,
                squeeze=[hand.squeeze_left, hand.squeeze_right],
                object_rise=float(X_WO_end.translation()[2] - z0),
                touches_table=on_table,
                touches_left_pad=hand.left,
                touches_right_pad=hand.right)
        result["wall_time"] = time.perf_counter() - start
        return result

    def _check(self, plant_context, z0: float) -> str | None:
        """Why the physics failed, or None."""
        x = self.plant.GetPositionsAndVelocities(plant_context)
        if not np.all(np.isfinite(x)):
            return "NaN in the state"
        X = self.plant.EvalBodyPoseInWorld(plant_context, self.object_body)
        p = X.translation()
        if p[2] < TABLE_TOP_Z - 0.05:  # its origin 5 cm under the top: not resting on it
            return "object fell through the table"
        if np.linalg.norm(p[:2]) > 2.0 or p[2] > 2.0:
            return "object flew off"
        return None


_WORLDS: dict[tuple[str, str], GraspWorld] = {}  # per worker process: the last object's world


def run_grasp_batch(payload: dict) -> list[dict]:
    """Executes a batch of grasps on one object (a job of tools/collect_grasps.py).

    `payload`: {"object_sdf", "object", "pose", "X_WO" (16 floats), "config" (EpisodeConfig
    fields), "grasps": [{"index", "kind", "part", "X_WG" (16 floats)}, ...]}. Returns one record per
    grasp: the grasp's fields and the episode's result, and "object_mass" when the episode set one
    (`EpisodeConfig.object_mass`). The world of the last object is kept for the next batch of this
    worker process.
    """
    config = EpisodeConfig(**payload.get("config", {}))
    key = (payload["object_sdf"], repr(config))
    if key not in _WORLDS:
        _WORLDS.clear()
        _WORLDS[key] = GraspWorld(payload["object_sdf"], config)
    world = _WORLDS[key]
    X_WO = np.array(payload["X_WO"], dtype=float).reshape(4, 4)
    mass = {"object_mass": config.object_mass} if config.object_mass > 0 else {}
    records = []
    for grasp in payload["grasps"]:
        result = world.run(X_WO, np.array(grasp["X_WG"], dtype=float).reshape(4, 4))
        records.append({"object": payload["object"], "pose": payload["pose"], **grasp, **result,
                        **mass})
    return records
