"""Scenario schema and loading.

A scenario has the shape of Drake's hardware_sim `Scenario` (model directives, `plant_config`,
`cameras`, `model_drivers`) plus our own blocks: `objects` (library objects placed on the table) and
`task` (target, task, placement, ground truth). Files are loaded with
`pydrake.common.yaml.yaml_load_typed`: unknown keys are errors, missing keys keep their defaults.
A file may hold one scenario at its root or several named entries (YAML anchors make variants:
`MugFull: {<<: *Mug, ...}`); `load_scenario(filename, scenario_name=...)` picks one.

Frames: W is the world, with its origin at the iiwa base on the floor plate and z up; the table top
frame T has its origin at the centre of the table-top surface, z up. Objects are placed by their
library id, a pose label, a position on the table (in T) and a yaw about the table normal.
"""


import dataclasses
import math
import typing
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml
from pydrake.common.schema import Transform
from pydrake.common.yaml import yaml_load_typed
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.parsing import AddModel, AddWeld, ModelDirective
from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.systems.analysis import SimulatorConfig
from pydrake.systems.sensors import CameraConfig

from tg_drake.errors import ScenarioError, unknown_name
from tg_drake.systems.supervisor import SupervisorConfig
from tg_drake.types import CONTAINMENTS, PART_LABELS, POSES, TASKS

# Where the table-top frame T sits in the world (its surface at the iiwa base height). Its centre
# is 0.75 m in front of the base: side grasps at 0.7–0.9 m and top grasps at 0.45–0.8 m are within
# reach there (an IK sweep over grasp heights 0.04–0.25 m; see tools notes in the README).
X_WT_DEFAULT = RigidTransform([0.75, 0.0, 0.0])

# The WSG body frame G on the iiwa's link 7: 0.114 m out along the flange axis, the approach
# direction +y_G along link 7's z axis (robot_facts.md: "mount").
X_7G = RigidTransform(RollPitchYaw(np.pi / 2, 0, np.pi / 2), [0, 0, 0.114])

# A posture that keeps the arm clear of the camera's view of the table (radians, joints 1–7).
IIWA_HOME = (0.0, -0.6, 0.0, -1.9, 0.0, 1.0, 0.0)


def _transform(X: RigidTransform, base_frame: str | None = None) -> Transform:
    t = Transform(X)
    if base_frame is not None:
        t.base_frame = base_frame
    return t


def default_directives() -> list[ModelDirective]:
    """The station: the iiwa on the floor at the world origin, the WSG on its flange, the table."""
    return [
        ModelDirective(add_model=AddModel(
            name="iiwa", file="package://tg_drake_models/iiwa14/iiwa14.urdf",
            default_joint_positions={f"iiwa_joint_{i + 1}": [q] for i, q in enumerate(IIWA_HOME)})),
        ModelDirective(add_weld=AddWeld(parent="world", child="iiwa::iiwa_link_0")),
        ModelDirective(add_model=AddModel(
            name="wsg", file="package://tg_drake_models/wsg_50/wsg_50.sdf",
            default_joint_positions={"left_finger_sliding_joint": [-0.055],
                                     "right_finger_sliding_joint": [0.055]})),
        ModelDirective(add_weld=AddWeld(parent="iiwa::iiwa_link_7", child="wsg::body",
                                        X_PC=_transform(X_7G))),
        ModelDirective(add_model=AddModel(
            name="table", file="package://tg_drake_models/table/table.sdf")),
        ModelDirective(add_weld=AddWeld(parent="world", child="table::table_top",
                                        X_PC=_transform(X_WT_DEFAULT))),
    ]


def default_cameras() -> dict[str, CameraConfig]:
    """One RGB-D camera across the table, looking down at it from the far side (facing the robot),
    at a height like the paper's platform camera; 640×480, 45° vertical field of view."""
    camera = CameraConfig(width=640, height=480, name="camera0",
                          renderer_class="RenderEngineVtk", rgb=True, depth=True, label=True)
    camera.focal = CameraConfig.FovDegrees(y=45.0)
    camera.z_far = 3.0
    camera.clipping_far = 3.0
    camera.X_PB = _transform(look_at([1.55, 0.0, 0.55], [0.75, 0.0, 0.05]))
    return {"camera0": camera}


def look_at(p_WC, p_WTarget, up_W=(0.0, 0.0, 1.0)) -> RigidTransform:
    """Pose of a Drake camera frame (x right, y down, z forward) at `p_WC` looking at `p_WTarget`."""
    p_WC, p_WTarget, up_W = map(np.asarray, (p_WC, p_WTarget, up_W))
    z = p_WTarget - p_WC
    z = z / np.linalg.norm(z)
    x = np.cross(z, up_W)
    if np.linalg.norm(x) < 1e-9:
        raise ScenarioError("camera looks along the up direction; choose another viewpoint")
    x = x / np.linalg.norm(x)
    y = np.cross(z, x)
    from pydrake.math import RotationMatrix
    return RigidTransform(RotationMatrix(np.column_stack([x, y, z])), p_WC)


@dataclass
class JointPdDriver:
    """Joint position control by the plant's own PD controllers on the joint actuators (implicit in
    SAP, so the step can be large). Desired positions and velocities enter the station's
    `<model>.desired_state` input. Gravity on the model is compensated (the KUKA and the WSG
    controllers compensate gravity of the arm and its configured payload)."""

    kp: float = 2000.0  # proportional gain [N·m/rad or N/m]
    kd: float = 100.0  # derivative gain [N·m·s/rad or N·s/m]
    gravity_compensation: bool = True  # do the model's own weights act on its joints?


@dataclass
class WsgPdDriver:
    """The WSG 50 under position control with a force limit: the plant's PD controllers on the two
    finger joints, their output clamped to `force_limit` (SAP respects actuator effort limits). The
    station's `wsg.position` input is the commanded opening width [m]."""

    kp: float = 2000.0  # [N/m]
    kd: float = 50.0  # [N·s/m]
    force_limit: float = 80.0  # [N] per finger: the WSG 50 drive's limit (robot_facts.md); at
    # 40 N a 0.55 kg hammer held by its handle turned out of the pads while carried.


@dataclass
class InverseDynamicsDriver:
    """The iiwa under an explicit inverse-dynamics controller (Drake's
    `InverseDynamicsController` on a model of the arm with the gripper as payload), its torques on
    the plant's actuation input. Drake's conventional choice; it needs a small time step (about
    1–2 ms) to stay stable, where the PD-in-plant driver runs at 5–10 ms."""

    kp: float = 100.0  # [1/s²]
    ki: float = 1.0  # [1/s³]
    kd: float = 20.0  # [1/s]


DriverConfig = typing.Union[JointPdDriver, WsgPdDriver, InverseDynamicsDriver]


def default_drivers() -> dict[str, DriverConfig]:
    return {"iiwa": JointPdDriver(), "wsg": WsgPdDriver()}


def default_plant_config() -> MultibodyPlantConfig:
    # Settings measured to hold a grasp on this kind of machine (robot_facts.md).
    return MultibodyPlantConfig(time_step=0.005, contact_model="hydroelastic_with_fallback",
                                discrete_contact_approximation="sap")


@dataclass
class ObjectPlacement:
    """A library object on the table."""

    id: str = ""  # object library id (`tg-drake objects` lists them)
    name: str = ""  # model instance name in the plant; defaults to the id
    pose: str = "upright"  # one of POSES suited to the object (library.yaml lists them)
    xy: list[float] = field(default_factory=lambda: [0.0, 0.0])  # position in the table frame [m]
    yaw: float = 0.0  # rotation about the table normal [deg]
    containment: str = "empty"  # "empty" or "full"; full adds the contents' mass (water)

    @property
    def instance_name(self) -> str:
        return self.name or self.id


@dataclass
class GroundTruth:
    """What an evaluation compares against. Task and part sets are set-valued, as in the paper."""

    category: str = ""  # the true category ("" = take it from the object library)
    tasks: list[str] = field(default_factory=list)  # tasks the object affords in this scene
    parts: list[str] = field(default_factory=list)  # acceptable pre-grasp parts for `task.task`
    reason: str = ""  # why these sets


@dataclass
class TaskConfig:
    target: str = ""  # instance name of the target object; "" = the first object
    task: str = ""  # one of TASKS; "" = infer the task
    place_xy: list[float] = field(default_factory=lambda: [0.0, -0.3])  # place target, table frame
    ground_truth: GroundTruth = field(default_factory=GroundTruth)


PERCEPTION_MODES = ("depth", "ground_truth")
GRASP_SELECTIONS = ("pipeline", "local_only")  # tg_drake.grasping.scoring.rank_grasps
THEORY_VARIANTS = ("specific", "general", "learned")  # "learned": tools/learn_theory.py


@dataclass
class PipelineConfig:
    """How the stages are set up. Lives in the scenario's `pipeline` block."""

    camera: str = "camera0"  # which camera perception looks through
    perception: str = "depth"  # "depth": perceive the rendered depth image; "ground_truth":
    # the object library's labelled surfaces at the true poses (the paper's S_SYN setting)
    category_theory: str = "specific"  # category model variant: specific | general
    grasp_theory: str = "specific"  # grasp model variant: specific | general
    use_prior: bool = True  # the kernel prior feeds the logic (PLM); False: uniform (PLM_uniform)
    prior_floor: float = 0.02  # the logic sees (1 − floor)·prior + floor/11: a perceived object's
    # kernel prior can miss its category, and a zero there would make the evidence impossible
    grasp_selection: str = "pipeline"  # how hypotheses are ranked: "pipeline" (P(part | task) ·
    # P(grasp | local shape)) or "local_only" (P(grasp | local shape) alone, the paper's Local)
    grasp_part: str | None = None  # only hypotheses of this PART_LABELS part are tried, ranked by
    # the DGI's P(grasp | shape) alone (the logic may give the part 0): for data collection
    supervisor: SupervisorConfig = field(default_factory=SupervisorConfig)  # the closed loop:
    # gate, re-queries, waiting for plans, execution monitor

    def validate(self, where: str = "pipeline") -> None:
        if self.perception not in PERCEPTION_MODES:
            raise unknown_name("perception mode", self.perception, PERCEPTION_MODES,
                               error=ScenarioError, field=f"{where}.perception")
        for name in ("category_theory", "grasp_theory"):
            if getattr(self, name) not in THEORY_VARIANTS:
                raise unknown_name("theory variant", getattr(self, name), THEORY_VARIANTS,
                                   error=ScenarioError, field=f"{where}.{name}")
        if self.grasp_selection not in GRASP_SELECTIONS:
            raise unknown_name("grasp selection", self.grasp_selection, GRASP_SELECTIONS,
                               error=ScenarioError, field=f"{where}.grasp_selection")
        if self.grasp_part is not None and self.grasp_part not in PART_LABELS:
            raise unknown_name("part", self.grasp_part, PART_LABELS, error=ScenarioError,
                               field=f"{where}.grasp_part")
        self.supervisor.validate(f"{where}.supervisor")


@dataclass
class Scenario:
    random_seed: int = 0
    simulation_duration: float = 20.0  # upper bound on simulated time for one run [s]
    simulator_config: SimulatorConfig = field(default_factory=lambda: SimulatorConfig(
        max_step_size=0.01, use_error_control=False, target_realtime_rate=0.0,
        publish_every_time_step=False))
    plant_config: MultibodyPlantConfig = field(default_factory=default_plant_config)
    directives: list[ModelDirective] = field(default_factory=default_directives)
    model_drivers: dict[str, DriverConfig] = field(default_factory=default_drivers)
    cameras: dict[str, CameraConfig] = field(default_factory=default_cameras)
    objects: list[ObjectPlacement] = field(default_factory=list)
    task: TaskConfig = field(default_factory=TaskConfig)
    pipeline: PipelineConfig = field(default_factory=PipelineConfig)
    # Table-top size (x, y) [m] used to check that objects stand on it.
    table_size: list[float] = field(default_factory=lambda: [0.8, 1.2])
    X_WT: Transform = field(default_factory=lambda: _transform(X_WT_DEFAULT))

    def target_placement(self) -> ObjectPlacement:
        if not self.objects:
            raise ScenarioError("the scenario has no objects", field="objects")
        if not self.task.target:
            return self.objects[0]
        for placement in self.objects:
            if placement.instance_name == self.task.target:
                return placement
        raise unknown_name("target object", self.task.target,
                           [p.instance_name for p in self.objects], error=ScenarioError,
                           field="task.target")


def load_scenario(filename: "str | Path | None" = None, *, scenario_name: str | None = None,
                  scenario_text: str | None = None) -> Scenario:
    """Loads a scenario: the file (or one named entry of it), then `scenario_text` layered on top.

    Raises ScenarioError naming the file and the problem for malformed YAML, unknown keys, unknown
    object ids, tasks or poses, and objects off the table.
    """
    where = str(filename) if filename is not None else "<text>"
    if filename is not None and not Path(filename).is_file():
        raise ScenarioError("no such scenario file", file=where)
    try:
        scenario = Scenario()
        if filename is not None:
            scenario = yaml_load_typed(schema=Scenario, filename=str(filename),
                                       child_name=scenario_name, defaults=scenario)
        if scenario_text:
            scenario = yaml_load_typed(schema=Scenario, data=scenario_text, defaults=scenario)
    except (RuntimeError, ValueError, TypeError, KeyError, AssertionError, yaml.YAMLError) as e:
        raise ScenarioError(_tidy_yaml_error(str(e)), file=where) from None
    validate(scenario, where=where)
    return scenario


def scenario_names(filename: str | Path) -> list[str]:
    """The named entries of a multi-scenario file (its top-level keys that are mappings)."""
    with open(filename) as f:
        data = yaml.safe_load(f) or {}
    schema_keys = {f.name for f in dataclasses.fields(Scenario)}
    return [k for k, v in data.items() if isinstance(v, dict) and k not in schema_keys]


def _tidy_yaml_error(message: str) -> str:
    # Drake's messages are precise but long; keep them, only trim whitespace.
    return " ".join(message.split())


def validate(scenario: Scenario, *, where: str = "<scenario>") -> None:
    """Checks names and geometry that YAML typing alone cannot."""
    names = set()
    half = np.asarray(scenario.table_size) / 2
    for i, placement in enumerate(scenario.objects):
        f = f"objects[{i}]"
        if not placement.id:
            raise ScenarioError("an object needs an `id` (see `tg-drake objects`)", file=where,
                                field=f + ".id")
        from tg_drake.objects import get_object  # the library loads only when objects are named

        try:
            obj = get_object(placement.id)
        except ScenarioError as e:
            raise ScenarioError(e.message, file=where, field=f + ".id") from None
        if placement.pose not in POSES:
            raise unknown_name("pose", placement.pose, POSES, error=ScenarioError, file=where,
                               field=f + ".pose")
        if placement.pose not in obj.poses:
            raise ScenarioError(f"pose {placement.pose!r} does not suit {placement.id}; allowed: "
                                + ", ".join(obj.poses), file=where, field=f + ".pose")
        if placement.containment not in CONTAINMENTS:
            raise unknown_name("containment", placement.containment, CONTAINMENTS,
                               error=ScenarioError, file=where, field=f + ".containment")
        if placement.containment == "full" and not obj.cavity_volume:
            raise ScenarioError(f"{placement.id} ({obj.category}) has no cavity to fill; allowed: "
                                "empty", file=where, field=f + ".containment")
        if len(placement.xy) != 2 or not all(math.isfinite(v) for v in placement.xy):
            raise ScenarioError(f"xy must be two finite numbers, got {placement.xy}", file=where,
                                field=f + ".xy")
        if np.any(np.abs(placement.xy) > half):
            raise ScenarioError(
                f"object at xy={placement.xy} is off the table (|x| ≤ {half[0]}, |y| ≤ {half[1]} "
                "in the table frame)", file=where, field=f + ".xy")
        if placement.instance_name in names:
            raise ScenarioError(f"two objects are named {placement.instance_name!r}; give each a "
                                "distinct `name`", file=where, field=f + ".name")
        names.add(placement.instance_name)
    task = scenario.task
    if task.task and task.task not in TASKS:
        raise unknown_name("task", task.task, TASKS, error=ScenarioError, file=where,
                           field="task.task")
    for t in task.ground_truth.tasks:
        if t not in TASKS:
            raise unknown_name("task", t, TASKS, error=ScenarioError, file=where,
                               field="task.ground_truth.tasks")
    if scenario.objects:
        try:
            scenario.target_placement()
        except ScenarioError as e:
            raise ScenarioError(e.message, file=where, field="task.target") from None
    try:
        scenario.pipeline.validate()
    except ScenarioError as e:
        raise ScenarioError(e.message, file=where, field=e.field) from None
    for name, driver in scenario.model_drivers.items():
        if name not in ("iiwa", "wsg"):
            raise unknown_name("model driver", name, ["iiwa", "wsg"], error=ScenarioError,
                               file=where, field="model_drivers")
