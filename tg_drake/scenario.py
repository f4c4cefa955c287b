"""Scenario schema and loading.

A scenario has the shape of Drake's hardware_sim `Scenario` (model directives, `plant_config`,
`cameras`, `model_drivers`) plus our own blocks: `objects` (library objects placed on the table) and
`task` (target, task, placement, ground truth), and `object_libraries` (user object library folders
whose objects `objects` may name). Files are loaded with
`pydrake.common.yaml.yaml_load_typed`: unknown keys are errors, missing keys keep their defaults.
A file may hold one scenario at its root or several named entries (YAML anchors make variants:
`MugFull: {<<: *Mug, ...}`); `load_scenario(filename, scenario_name=...)` picks one.

Frames: W is the world, with its origin at the iiwa base on the floor plate and z up; the table top
frame T has its origin at the centre of the table-top surface, z up. Objects are placed by their
library id (or a mesh file or model folder, imported through `tg_drake.importing` and cached), a
pose label (or `resting: auto | K`, the K-th most probable stable pose), a position on the table
(in T) and a yaw about the table normal. Relative paths (`mesh`, `labels`, `object_libraries`)
resolve against the scenario file's folder; `package://tg_drake_models/...` works too.
"""


import dataclasses
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml
from pydrake.common.schema import Transform
from pydrake.common.yaml import yaml_load_typed
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.parsing import ModelDirective
from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.systems.analysis import SimulatorConfig
from pydrake.systems.sensors import CameraConfig
from scipy.spatial import ConvexHull

from tg_drake.errors import ModelError, RuleError, ScenarioError, unknown_name
from tg_drake.grasping.expansion import ExpansionConfig
from tg_drake.grasping.feasibility import FeasibilityConfig
from tg_drake.kernels.database import SOURCES as KERNEL_SOURCES
from tg_drake.kernels.database import KernelPriorConfig
from tg_drake.logic.engine import LogicQueryConfig
from tg_drake.models import models_root
from tg_drake.objects import PACKAGE, add_library, get_object, mesh, register_object
from tg_drake.perception.config import PerceptionConfig
from tg_drake.perception.sensor_model import IdealDepth, SensorModel, StructuredLight
from tg_drake.planning.handover import ReceiverConfig
from tg_drake.planning.planner import PlannerConfig
from tg_drake.planning.task_motion import TaskMotionConfig
from tg_drake.robot import WSG_FORCE_LIMIT, X_7G_RPY, X_7G_XYZ
from tg_drake.robot_plants import default_directives
from tg_drake.schema_check import SchemaError, check_document, load_raw
from tg_drake.table import TABLE_SIZE, X_WT_DEFAULT, table_size_problem
from tg_drake.tasks.contents import (
    DISPENSER_WALL,
    ContentsConfig,
    DispenserConfig,
    container_sites,
)
from tg_drake.types import CATEGORIES, CONTAINMENTS, PART_LABELS, POSES, TASKS

# The WSG body frame G on the iiwa's link 7 (tg_drake.robot: the mount).
X_7G = RigidTransform(RollPitchYaw(*X_7G_RPY), X_7G_XYZ)


def _transform(X: RigidTransform, base_frame: str | None = None) -> Transform:
    t = Transform(X)
    if base_frame is not None:
        t.base_frame = base_frame
    return t


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
    """Pose of a Drake camera frame (x right, y down, z forward) at `p_WC` looking at
    `p_WTarget`."""
    p_WC, p_WTarget, up_W = map(np.asarray, (p_WC, p_WTarget, up_W))
    z = p_WTarget - p_WC
    z = z / np.linalg.norm(z)
    x = np.cross(z, up_W)
    if np.linalg.norm(x) < 1e-9:
        raise ScenarioError("camera looks along the up direction; choose another viewpoint")
    x = x / np.linalg.norm(x)
    y = np.cross(z, x)
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
    force_limit: float = WSG_FORCE_LIMIT  # [N] per finger: the WSG 50 drive's limit; at
    # 40 N a 0.55 kg hammer held by its handle turned out of the pads while carried.
    coupled: bool = True  # the fingers move symmetrically, as the gripper's one drive moves
    # them (a coupler constraint, `tg_drake.robot_plants.couple_fingers`).


@dataclass
class InverseDynamicsDriver:
    """The iiwa under an explicit inverse-dynamics controller (Drake's
    `InverseDynamicsController` on a model of the arm with the gripper as payload), its torques on
    the plant's actuation input. Drake's conventional choice; it needs a small time step (about
    1–2 ms) to stay stable, where the PD-in-plant driver runs at 5–10 ms."""

    kp: float = 100.0  # [1/s²]
    ki: float = 1.0  # [1/s³]
    kd: float = 20.0  # [1/s]


DriverConfig = JointPdDriver | WsgPdDriver | InverseDynamicsDriver


def default_drivers() -> dict[str, DriverConfig]:
    return {"iiwa": JointPdDriver(), "wsg": WsgPdDriver()}


def default_plant_config() -> MultibodyPlantConfig:
    # Settings measured to hold a grasp on this kind of machine (docs/design.md, "Simulation
    # settings").
    return MultibodyPlantConfig(time_step=0.005, contact_model="hydroelastic_with_fallback",
                                discrete_contact_approximation="sap")


# A `mesh:` entry's import settings (tg_drake.importing.ImportOptions).
UNITS = ("auto", "m", "cm", "mm", "inch")
UP_AXES = ("z", "y", "x")
COLLISION_BACKENDS = ("coacd", "vhacd")
MESH_FIELDS = ("category", "units", "up_axis", "mass", "density", "labels", "collision")


@dataclass
class ObjectPlacement:
    """An object on the table: a library object (`id`) or a mesh to import (`mesh`), exactly
    one of them."""

    id: str = ""  # object library id (`tg-drake objects` lists them); set to the imported
    # object's id for a `mesh` entry once the scenario is validated
    name: str = ""  # model instance name in the plant; defaults to the id
    pose: str = "upright"  # one of POSES suited to the object (library.yaml lists them)
    xy: list[float] = field(default_factory=lambda: [0.0, 0.0])  # position in the table frame [m]
    yaw: float = 0.0  # rotation about the table normal [deg]
    containment: str = "empty"  # "empty" or "full"; full adds the contents' mass (water)
    resting: int | str | None = None  # instead of pose: "auto" (the most probable named stable
    # pose) or K (the K-th most probable, 0 first, tilted ones included: it rests as found, and
    # `pose` becomes the nearest label), for objects whose library lists stable poses
    mesh: str = ""  # a mesh file (OBJ STL PLY GLB DAE), a model folder (Google Scanned Objects,
    # YCB) or a one-body SDF/URDF to import: a path relative to the scenario file, or package://
    category: str = ""  # mesh entries: the true category (ground truth for evaluation only;
    # perception never reads it); "" = the importer decides
    units: str = "auto"  # mesh entries: one of UNITS; auto infers them from the size
    up_axis: str = "z"  # mesh entries: the mesh's up axis, one of UP_AXES
    mass: float | None = None  # mesh entries: [kg]; with neither mass nor density, a density
    density: float | None = None  # prior of the category [kg/m³]
    labels: str = ""  # mesh entries: a per-vertex part label file (.npy) of the mesh
    collision: str = ""  # mesh entries: convex decomposition, one of COLLISION_BACKENDS; "" = the
    # importer's default

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
    place_on: str = ""  # p&pOn: the name of the surface (`surfaces`) to place the object on;
    # "" = the first surface. The object goes to the surface's centre, not to `place_xy`.
    pour_into: str = ""  # pourOut: the instance name of the scene object poured into (a bowl)


@dataclass
class SurfaceConfig:
    """A box standing on the table (a shelf, a board), welded to it with a compliant-hydroelastic
    top like the table's; p&pOn places the object on one."""

    name: str = ""  # unique among the surfaces
    xy: list[float] = field(default_factory=lambda: [0.0, 0.0])  # centre, table frame [m]
    size: list[float] = field(default_factory=lambda: [0.2, 0.2, 0.05])  # x, y, height [m]


@dataclass
class DepthPerception:
    """Perception of the rendered depth image of one camera (paper III): table plane, objects,
    symmetry-based completion, pose, parts and pre-grasp hypotheses."""

    camera: str = "camera0"  # which of the scenario's `cameras` perception looks through
    config: PerceptionConfig = field(default_factory=PerceptionConfig)  # every step's parameters
    sensor: SensorModel = field(default_factory=IdealDepth)  # what the camera measures of the
    # rendered depth: `!IdealDepth {}` (the render as it is) or `!StructuredLight {...}` (a
    # triangulating camera's noise and missing pixels; defaults: an Intel RealSense D415)


@dataclass
class GroundTruthPerception:
    """The object library's labelled surfaces at the true poses, for the synthetic
    (perfect-perception) evaluation: the paper's S_SYN setting. Never reads the camera."""

    spacing: float = 0.004  # [m] the meshes' surfaces are sampled this far apart


PerceptionVariant = DepthPerception | GroundTruthPerception


@dataclass
class DgiScorer:
    """score = P(part | task) · P(grasp | local shape): the paper's pipeline (section V)."""

    model: str = ""  # a DGI model file (tools/train_dgi.py writes one); "" = the shipped model


@dataclass
class LocalOnly:
    """score = P(grasp | local shape) alone, ignoring the logic: the paper's Local baseline."""

    model: str = ""  # as DgiScorer.model


@dataclass
class OnePart:
    """Only the hypotheses of `part` are scored, by P(grasp | local shape) alone, even where the
    logic gives that part 0; every other hypothesis scores 0. For collecting grasp outcomes per
    part (tools/learn_theory.py), so that outcomes exist for parts the logic would not pick."""

    part: str = "middle"  # one of PART_LABELS
    model: str = ""  # as DgiScorer.model


@dataclass
class RandomPart:
    """The random-part baseline: one part drawn uniformly among the parts that have a pre-grasp
    hypothesis (with `seed`, so a run repeats), its hypotheses ranked by P(grasp | local shape);
    every other hypothesis scores 0."""

    seed: int = 0  # seeds the draw (the evaluation sets it from the case)
    model: str = ""  # as DgiScorer.model


ScoringVariant = DgiScorer | LocalOnly | OnePart | RandomPart

# The core's name (tg_drake.grasping.scoring.SELECTIONS) of each scoring variant.
SELECTION_OF_SCORING = {DgiScorer: "pipeline", LocalOnly: "local_only", OnePart: "one_part",
                        RandomPart: "random_part"}


@dataclass
class SupervisorConfig:
    """The closed loop's policy. Lives in the scenario's `pipeline.supervisor` block."""

    min_grasp_probability: float = 0.03  # [probability] below this P(some part is grasped |
    # observations) the logic is taken to rule grasping out (an upside-down pan: 0.015; the
    # paper's Fig. 1 cup: 0.13)
    max_requeries: int = 3  # re-queries of the logic with collision(Part) evidence
    planning_start: float = 0.05  # [s] simulated time of the first gate check
    planning_timeout: float = 2.0  # [s] simulated time after planning_start by which a plan
    # must exist (planning takes no simulated time; each attempt waits for a planning event)
    period: float = 0.005  # [s] spacing of the supervisor's checks (a monitor check happens at
    # the first check at or after the plan's key time)
    min_rise_ratio: float = 0.5  # [1] during the lift the object must rise at least this share
    # of the gripper's rise, else it slipped
    max_regrasps: int = 1  # place-and-regrasp legs (p&pIn*: the object put down in an
    # intermediate pose, perceived again and picked again) allowed before the final leg
    max_retries: int = 0  # after a missed grasp or a failed lift: look again (every plan then
    # ends with the arm back at its start) and plan again from the new scene, at most this many
    # times (0: off, the run ends missed / slipped)
    max_reseats: int = 1  # at the place, when the object still touches a pad once the pads have
    # opened, the plan re-seats it (closes on it where it stands and opens again) before the
    # retreat, at most this many times per plan (0: off, the retreat goes ahead)
    release_check_delay: float = 0.05  # [s] after the pads are commanded open at the place, the
    # touch check (within PlannerConfig.release_dwell, less the planner's period)

    def validate(self, where: str = "pipeline.supervisor") -> None:
        checks = (("min_grasp_probability", 0.0 <= self.min_grasp_probability <= 1.0, "in [0, 1]"),
                  ("max_requeries", self.max_requeries >= 0, ">= 0"),
                  ("planning_start", self.planning_start >= 0.0, ">= 0 s"),
                  ("planning_timeout", self.planning_timeout > 0.0, "> 0 s"),
                  ("period", self.period > 0.0, "> 0 s"),
                  ("min_rise_ratio", 0.0 <= self.min_rise_ratio <= 1.0, "in [0, 1]"),
                  ("max_regrasps", self.max_regrasps >= 0, ">= 0"),
                  ("max_retries", self.max_retries >= 0, ">= 0"),
                  ("max_reseats", self.max_reseats >= 0, ">= 0"),
                  ("release_check_delay", self.release_check_delay >= 0.0, ">= 0 s"))
        for name, ok, allowed in checks:
            if not ok:
                raise ScenarioError(f"must be {allowed}, got {getattr(self, name)}",
                                    field=f"{where}.{name}")


def _pipeline_logic() -> LogicQueryConfig:
    # The logic sees (1 − floor)·prior + floor/11 with the floor the kernel database fitted for
    # its kind of query (None): a perceived object's kernel prior can miss its category, and a
    # zero there would make the evidence impossible.
    return LogicQueryConfig(prior_floor=None)


@dataclass
class PipelineConfig:
    """Every stage's settings. Lives in the scenario's `pipeline` block; alternatives are tagged
    (`perception: !GroundTruthPerception {}`, `scoring: !LocalOnly {}`)."""

    perception: PerceptionVariant = field(default_factory=DepthPerception)
    prior: KernelPriorConfig = field(default_factory=KernelPriorConfig)  # kernel category prior
    logic: LogicQueryConfig = field(default_factory=_pipeline_logic)  # theory variants, prior use
    scoring: ScoringVariant = field(default_factory=DgiScorer)  # how hypotheses are ranked
    feasibility: FeasibilityConfig = field(default_factory=FeasibilityConfig)  # collision and
    # P(hold) of the poses that will be executed (tg_drake.grasping.feasibility)
    expansion: ExpansionConfig = field(default_factory=ExpansionConfig)  # hypothesis → the
    # poses that may be executed, scored by the DGI (tg_drake.grasping.expansion)
    planner: PlannerConfig = field(default_factory=PlannerConfig)  # the pick-and-place plan
    supervisor: SupervisorConfig = field(default_factory=SupervisorConfig)  # the closed loop:
    # gate, re-queries, waiting for plans, execution monitor
    tasks: TaskMotionConfig = field(default_factory=TaskMotionConfig)  # the task motions:
    # reorienting to a resting pose, placing on a surface, pouring

    def validate(self, where: str = "pipeline") -> None:
        """Checks names the YAML types cannot; raises ScenarioError naming the field."""
        if isinstance(self.perception, DepthPerception) and not self.perception.camera:
            raise ScenarioError("perception needs a camera name",
                                field=f"{where}.perception.camera")
        if isinstance(self.perception, DepthPerception) and isinstance(self.perception.sensor,
                                                                      StructuredLight):
            for f, problem in self.perception.sensor.validate(f"{where}.perception.sensor"):
                raise ScenarioError(problem, field=f)
        if isinstance(self.perception, GroundTruthPerception) and not self.perception.spacing > 0:
            raise ScenarioError(f"spacing must be > 0 [m], got {self.perception.spacing}",
                                field=f"{where}.perception.spacing")
        try:
            self.logic.theory()
        except RuleError as e:
            raise ScenarioError(e.message, field=f"{where}.logic.{e.field}") from None
        if self.logic.prior_floor is not None and not 0.0 <= self.logic.prior_floor <= 1.0:
            raise ScenarioError(f"prior_floor must be in [0, 1], got {self.logic.prior_floor}",
                                field=f"{where}.logic.prior_floor")
        if self.prior.clouds is not None and self.prior.clouds not in KERNEL_SOURCES:
            raise unknown_name("cloud source", self.prior.clouds, KERNEL_SOURCES,
                               error=ScenarioError, field=f"{where}.prior.clouds")
        if isinstance(self.scoring, OnePart) and self.scoring.part not in PART_LABELS:
            raise unknown_name("part", self.scoring.part, PART_LABELS, error=ScenarioError,
                               field=f"{where}.scoring.part")
        if self.scoring.model and not Path(self.scoring.model).is_file():
            raise ScenarioError(f"no such DGI model file {self.scoring.model!r}",
                                field=f"{where}.scoring.model")
        self.expansion.validate(f"{where}.expansion")
        self.planner.validate(f"{where}.planner")
        self.feasibility.validate(f"{where}.feasibility")
        self.supervisor.validate(f"{where}.supervisor")
        self.tasks.validate(f"{where}.tasks")

    @property
    def ground_truth_perception(self) -> bool:
        return isinstance(self.perception, GroundTruthPerception)

    def prior_config(self) -> KernelPriorConfig:
        """The kernel prior's settings, its query clouds set from the perception variant unless
        given (ground-truth samplings for ground-truth perception, else perceived clouds)."""
        if self.prior.clouds is not None:
            return self.prior
        return dataclasses.replace(
            self.prior, clouds="ground_truth" if self.ground_truth_perception else "perceived")

    @property
    def selection(self) -> str:
        """The scoring core's name of the scoring variant."""
        return SELECTION_OF_SCORING[type(self.scoring)]


@dataclass
class Scenario:
    random_seed: int = 0
    simulation_duration: float = 40.0  # [s] upper bound on simulated time for one run: a guard
    # against a run that never finishes, above any plan's length (20 s cut 3 of 177 executed
    # S_GRASP/S_ROBOT runs mid-plan: a pass's plan runs 23.7 s; the longest finished run 20.0 s)
    simulator_config: SimulatorConfig = field(default_factory=lambda: SimulatorConfig(
        max_step_size=0.01, use_error_control=False, target_realtime_rate=0.0,
        publish_every_time_step=False))
    plant_config: MultibodyPlantConfig = field(default_factory=default_plant_config)
    directives: list[ModelDirective] = field(default_factory=default_directives)
    model_drivers: dict[str, DriverConfig] = field(default_factory=default_drivers)
    cameras: dict[str, CameraConfig] = field(default_factory=default_cameras)
    objects: list[ObjectPlacement] = field(default_factory=list)
    object_libraries: list[str] = field(default_factory=list)  # user library folders (relative
    # to the scenario file) whose objects `objects` may name
    task: TaskConfig = field(default_factory=TaskConfig)
    surfaces: list[SurfaceConfig] = field(default_factory=list)  # boxes on the table (p&pOn)
    pipeline: PipelineConfig = field(default_factory=PipelineConfig)
    # The table: its top's size (x, y) [m] and where its top frame T sits in the world. The station
    # builds the table from these (tg_drake.table); objects must stand within the top.
    table_size: list[float] = field(default_factory=lambda: list(TABLE_SIZE))
    X_WT: Transform = field(default_factory=lambda: _transform(X_WT_DEFAULT))
    # Contents of full containers ("mass" or "spheres") and an optional dispenser of spheres
    # (pourIn); tg_drake.tasks.contents.
    contents: ContentsConfig = field(default_factory=ContentsConfig)
    dispenser: DispenserConfig | None = None
    receiver: ReceiverConfig | None = None  # pass: the second gripper that takes the object
    # (tg_drake.planning.handover; table frame); None: the default one when the task is pass

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
        text = Path(filename).read_text(encoding="utf-8") if filename is not None else None
    except UnicodeDecodeError as e:
        raise ScenarioError(f"not a UTF-8 text file ({e.reason} at byte {e.start})",
                            file=where) from None
    except OSError as e:
        raise ScenarioError(f"cannot read the file: {e.strerror}", file=where) from None
    _check_raw(text, scenario_name, scenario_text, where)
    try:
        scenario = Scenario()
        if filename is not None:
            scenario = yaml_load_typed(schema=Scenario, filename=str(filename),
                                       child_name=scenario_name, defaults=scenario)
        if scenario_text:
            scenario = yaml_load_typed(schema=Scenario, data=scenario_text, defaults=scenario)
    except (RuntimeError, ValueError, TypeError, KeyError, AssertionError, yaml.YAMLError) as e:
        raise ScenarioError(_tidy_yaml_error(str(e)), file=where) from None
    validate(scenario, where=where,
             base_dir=Path(filename).parent if filename is not None else None)
    return scenario


def _check_raw(file_text: str | None, scenario_name: str | None, scenario_text: str | None,
               where: str) -> None:
    """Checks the documents against the schema (`tg_drake.schema_check`), so that a mistake is
    reported with its field path and the allowed keys or the expected type."""
    for text, name in ((file_text, scenario_name), (scenario_text, None)):
        if not text:
            continue
        try:
            doc = load_raw(text)
        except yaml.YAMLError as e:
            raise ScenarioError(f"malformed YAML: {_tidy_yaml_error(str(e))}", file=where) from None
        except SchemaError as e:
            raise ScenarioError(e.message, file=where) from None
        if name is not None:
            entries = [k for k, v in (doc or {}).items() if isinstance(v, dict)] \
                if isinstance(doc, dict) else []
            if name not in entries:
                raise unknown_name("scenario", name, entries, error=ScenarioError, file=where,
                                   field="--name")
            doc = doc[name]
        if doc is None:
            continue
        try:
            check_document(doc, Scenario)
        except SchemaError as e:
            raise ScenarioError(e.message, file=where if text is file_text else "<text>",
                                field=e.path) from None
        _check_raw_objects(doc, where if text is file_text else "<text>")


def _check_raw_objects(doc, where: str) -> None:
    """`id` or `mesh` and `pose` or `resting`, as written (the loaded dataclass has defaults)."""
    objects = doc.get("objects") if isinstance(doc, dict) else None
    for i, entry in enumerate(objects if isinstance(objects, list) else []):
        if not isinstance(entry, dict):
            continue
        given = {k for k, v in entry.items() if v not in (None, "")}  # a dump writes defaults
        if ("id" in given) == ("mesh" in given):
            raise ScenarioError(
                ("both `id` and `mesh` are given" if "id" in given else "neither `id` nor `mesh` "
                 "is given") + "; an object is either `{id: ID, ...}` (a library object, see "
                 "`tg-drake objects`) or `{mesh: FILE_OR_FOLDER, ...}` (imported)",
                file=where, field=f"objects[{i}]")
        if "pose" in given and "resting" in given:
            raise ScenarioError("give either `pose` (upright, sideways, upsidedown) or "
                                "`resting` (auto or K), not both", file=where,
                                field=f"objects[{i}].resting")


def scenario_names(filename: str | Path) -> list[str]:
    """The named entries of a multi-scenario file (its top-level keys that are mappings)."""
    data = load_raw(Path(filename).read_text()) or {}
    schema_keys = {f.name for f in dataclasses.fields(Scenario)}
    return [k for k, v in data.items() if isinstance(v, dict) and k not in schema_keys]


MAX_MESSAGE = 400  # characters of a loader's message quoted in ours


def _tidy_yaml_error(message: str) -> str:
    # Drake's messages are precise but can quote a whole value: trim whitespace and length.
    message = " ".join(message.split())
    return message if len(message) <= MAX_MESSAGE else message[:MAX_MESSAGE] + "…"


def validate(scenario: Scenario, *, where: str = "<scenario>",
             base_dir: str | Path | None = None) -> None:
    """Checks names and geometry that YAML typing alone cannot. First resolves the scenario's
    objects (`resolve_objects`: user libraries registered, mesh entries imported, paths made
    absolute against `base_dir`, the current folder when None)."""
    names = set()
    problem = table_size_problem(scenario.table_size)
    if problem:
        raise ScenarioError(problem, file=where, field="table_size")
    resolve_objects(scenario, where=where, base_dir=base_dir)
    half = np.asarray(scenario.table_size) / 2
    for i, placement in enumerate(scenario.objects):
        f = f"objects[{i}]"
        try:
            obj = get_object(placement.id)
        except ScenarioError as e:
            raise ScenarioError(e.message, file=where, field=f + ".id") from None
        if placement.resting is not None:
            _resolve_resting(placement, obj, where, f)
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
    if task.ground_truth.category and task.ground_truth.category not in CATEGORIES:
        raise unknown_name("category", task.ground_truth.category, CATEGORIES,
                           error=ScenarioError, file=where, field="task.ground_truth.category")
    for part in task.ground_truth.parts:
        if part not in PART_LABELS:
            raise unknown_name("part", part, PART_LABELS, error=ScenarioError, file=where,
                               field="task.ground_truth.parts")
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
    perception = scenario.pipeline.perception
    if isinstance(perception, DepthPerception) and perception.camera not in scenario.cameras:
        raise unknown_name("camera", perception.camera, list(scenario.cameras),
                           error=ScenarioError, file=where, field="pipeline.perception.camera")
    _replace_retired_models(scenario, where)
    for name in scenario.model_drivers:
        if name not in ("iiwa", "wsg"):
            raise unknown_name("model driver", name, ["iiwa", "wsg"], error=ScenarioError,
                               file=where, field="model_drivers")
    try:
        _validate_simulation(scenario)
        _validate_geometry(scenario)
        _validate_surfaces(scenario)
        _validate_contents(scenario)
        if scenario.receiver is not None:
            scenario.receiver.validate("receiver")
    except ScenarioError as e:
        raise ScenarioError(e.message, file=where, field=e.field) from None


# Shipped model files that were replaced, and their replacements (the same model): a scenario
# written before (an exported case, a run's result.json `config`) names the old file.
RETIRED_MODEL_FILES = {
    "package://tg_drake_models/wsg_50/wsg_50.sdf": "package://tg_drake_models/wsg_50/wsg_50.urdf",
}


def _replace_retired_models(scenario: Scenario, where: str) -> None:
    """Points the scenario's directives that add a retired model file (RETIRED_MODEL_FILES) at
    its replacement, with a warning on stderr naming the field."""
    for i, directive in enumerate(scenario.directives or ()):
        model = directive.add_model
        new = RETIRED_MODEL_FILES.get(model.file) if model is not None else None
        if new:
            print(f"warning: {where}: directives[{i}].add_model.file {model.file} is retired; "
                  f"using {new}, the same model", file=sys.stderr)
            model.file = new


def _resolve_path(text: str, base_dir: Path | None) -> Path:
    """A scenario's path: package://tg_drake_models/... in the shipped models, else relative to
    `base_dir` (the scenario file's folder; the current folder when None)."""
    if text.startswith("package://"):
        package, _, rest = text[len("package://"):].partition("/")
        if package != PACKAGE:
            raise ScenarioError(f"unknown package {package!r} in {text!r}; allowed: "
                                f"{PACKAGE}")
        return Path(models_root()) / rest
    path = Path(text).expanduser()
    if not path.is_absolute():
        path = (Path(base_dir) if base_dir is not None else Path.cwd()) / path
    return path.resolve()


def resolve_objects(scenario: Scenario, *, where: str = "<scenario>",
                    base_dir: str | Path | None = None) -> None:
    """Makes the scenario's objects known to `tg_drake.objects.get_object`: registers its
    `object_libraries` and imports its `mesh` entries (cached by content: a second call imports
    nothing), setting each mesh entry's `id` to the imported object's. Paths are made absolute
    (against `base_dir`, else the current folder), so that calling it again anywhere — the station
    does — gives the same objects."""
    scenario.object_libraries[:] = add_object_libraries(scenario.object_libraries, where=where,
                                                        base_dir=base_dir)
    for i, placement in enumerate(scenario.objects):
        f = f"objects[{i}]"
        if not placement.mesh:
            if not placement.id:
                raise ScenarioError("an object needs an `id` (see `tg-drake objects`) or a "
                                    "`mesh` to import", file=where, field=f + ".id")
            given = [k for k in MESH_FIELDS
                     if getattr(placement, k) != getattr(_DEFAULT_PLACEMENT, k)]
            if given:
                raise ScenarioError(f"{', '.join(given)} apply to `mesh` entries only; a library "
                                    "object's come from its library", file=where,
                                    field=f"{f}.{given[0]}")
            continue
        _check_mesh_entry(placement, where, f)
        try:
            path = _resolve_path(placement.mesh, base_dir)
            labels = _resolve_path(placement.labels, base_dir) if placement.labels else None
        except ScenarioError as e:
            raise ScenarioError(e.message, file=where, field=f + ".mesh") from None
        if not path.exists():
            raise ScenarioError(f"no such mesh file or model folder {str(path)!r}", file=where,
                                field=f + ".mesh")
        if labels is not None and not labels.is_file():
            raise ScenarioError(f"no such part label file {str(labels)!r}", file=where,
                                field=f + ".labels")
        placement.mesh = str(path)
        if labels is not None:
            placement.labels = str(labels)
        obj = _import_mesh(placement, path, labels, where, f)
        if placement.id and placement.id != obj.id:
            raise ScenarioError(f"both `id` ({placement.id!r}) and `mesh` are given; an object is "
                                "either `{id: ID, ...}` or `{mesh: FILE_OR_FOLDER, ...}`",
                                file=where, field=f)
        placement.id = obj.id


_DEFAULT_PLACEMENT = ObjectPlacement()


def add_object_libraries(folders, *, where: str = "<scenario>", base_dir: str | Path | None = None,
                         field: str = "object_libraries") -> list[str]:
    """Registers user object libraries (`tg_drake.objects.add_library`) named by paths relative to
    `base_dir` (or package://); returns their absolute paths. ScenarioError naming `field`[i]."""
    out = []
    for i, text in enumerate(folders):
        try:
            path = _resolve_path(text, base_dir)
            add_library(path)
        except (ScenarioError, ModelError) as e:
            raise ScenarioError(e.message + (f" ({e.file})" if e.file else ""), file=where,
                                field=f"{field}[{i}]") from None
        out.append(str(path))
    return out


def _check_mesh_entry(placement: ObjectPlacement, where: str, f: str) -> None:
    for name, allowed in (("units", UNITS), ("up_axis", UP_AXES)):
        if getattr(placement, name) not in allowed:
            raise unknown_name(name.replace("_", " "), getattr(placement, name), allowed,
                               error=ScenarioError, file=where, field=f"{f}.{name}")
    if placement.category and placement.category not in CATEGORIES:
        raise unknown_name("category", placement.category, CATEGORIES, error=ScenarioError,
                           file=where, field=f + ".category")
    if placement.collision and placement.collision not in COLLISION_BACKENDS:
        raise unknown_name("collision backend", placement.collision, COLLISION_BACKENDS,
                           error=ScenarioError, file=where, field=f + ".collision")
    if placement.mass is not None and placement.density is not None:
        raise ScenarioError("give `mass` or `density`, not both", file=where,
                            field=f + ".density")
    for name, unit in (("mass", "kg"), ("density", "kg/m³")):
        value = getattr(placement, name)
        if value is not None and not (_finite(value) and value > 0):
            raise ScenarioError(f"must be a finite number > 0 [{unit}], got {value}",
                                file=where, field=f"{f}.{name}")


def _import_mesh(placement: ObjectPlacement, path: Path, labels: Path | None, where: str,
                 f: str):
    """The object imported from `path` (tg_drake.importing, cached), registered."""
    from tg_drake.importing import ImportOptions, import_cached  # the import is heavy and rare
    from tg_drake.importing.library import unclaimed_id

    options = dict(category=placement.category or None, units=placement.units,
                   up_axis=placement.up_axis, mass=placement.mass, density=placement.density,
                   labels=labels)
    if placement.collision:
        options["collision"] = placement.collision
    try:
        return register_object(import_cached(path, unclaimed_id(path, ImportOptions(**options))))
    except (ScenarioError, ModelError) as e:
        field = e.field if e.field in MESH_FIELDS else "mesh"
        raise ScenarioError(e.message + (f" ({e.file})" if e.file else ""), file=where,
                            field=f"{f}.{field}") from None


def _resolve_resting(placement: ObjectPlacement, obj, where: str, f: str) -> None:
    """`resting: auto | K` → K (an int: the object rests in its K-th most probable stable pose, as
    found) and `pose`, the label it has for perception's ground truth and the evaluation: the
    stable pose's own name, or for a tilted pose with no name the nearest of the object's poses
    (`nearest_pose_label`). auto is the most probable stable pose that has a name."""
    k = placement.resting
    if k == "auto":
        named = [j for j, s in enumerate(obj.stable_poses) if s.pose in obj.poses]
        k = named[0] if named else 0
    if isinstance(k, str):
        try:
            k = int(k)
        except ValueError:
            raise ScenarioError(f"resting must be auto or a whole number K >= 0, got {k!r}",
                                file=where, field=f + ".resting") from None
    try:
        stable = obj.stable_pose(k)
    except ScenarioError as e:
        raise ScenarioError(e.message, file=where, field=f + ".resting") from None
    placement.resting = k
    placement.pose = (stable.pose if stable.pose in obj.poses
                      else nearest_pose_label(stable.X_TO, obj))


def nearest_pose_label(X_TO: np.ndarray, obj) -> str:
    """The object's pose label (among `obj.poses`) whose direction of O's z axis in the table
    frame is nearest to X_TO's: z up is upright, down upsidedown, horizontal sideways; a tool's
    only rest, flat, has z up (it is called sideways)."""
    up = float(np.clip(np.asarray(X_TO)[2, 2], -1.0, 1.0))  # z_O · z_T
    tilt = ({"sideways": math.acos(up)} if obj.is_tool else
            {"upright": math.acos(up), "upsidedown": math.acos(-up),
             "sideways": math.asin(abs(up))})
    names = [name for name in obj.poses if name in tilt] or list(tilt)  # none named: any
    return min(names, key=tilt.__getitem__)


def placement_X_TO(placement: ObjectPlacement, obj) -> np.ndarray:
    """4×4 X_TO of a placed object before its xy and yaw: its stable pose K when `resting` was
    resolved to K, else the library's resting transform for its `pose`."""
    if isinstance(placement.resting, int) and not isinstance(placement.resting, bool):
        return np.asarray(obj.stable_pose(placement.resting).X_TO)
    return np.asarray(obj.resting_pose(placement.pose).X_TO)


# Drake's names (MultibodyPlantConfig): contact models, discrete approximations, surfaces.
CONTACT_MODELS = ("point", "hydroelastic", "hydroelastic_with_fallback")
DISCRETE_APPROXIMATIONS = ("tamsi", "sap", "similar", "lagged")
CONTACT_SURFACES = ("triangle", "polygon")


def _finite(value) -> bool:
    try:
        return bool(np.all(np.isfinite(np.asarray(value, float))))
    except (TypeError, ValueError):
        return False


def _positive(value, field: str, unit: str, *, allow_zero: bool = False) -> None:
    ok = _finite(value) and (value >= 0 if allow_zero else value > 0)
    if not ok:
        raise ScenarioError(f"must be a finite number {'≥' if allow_zero else '>'} 0 [{unit}], "
                            f"got {value}", field=field)


def _validate_simulation(scenario: Scenario) -> None:
    """The plant, the drivers, the cameras and the simulator: values that would hang, diverge or
    fail deep inside Drake."""
    plant = scenario.plant_config
    _positive(plant.time_step, "plant_config.time_step", "s")  # 0 makes a continuous plant
    _positive(plant.penetration_allowance, "plant_config.penetration_allowance", "m")
    _positive(plant.stiction_tolerance, "plant_config.stiction_tolerance", "m/s")
    for name, allowed in (("contact_model", CONTACT_MODELS),
                          ("discrete_contact_approximation", DISCRETE_APPROXIMATIONS),
                          ("contact_surface_representation", CONTACT_SURFACES)):
        if getattr(plant, name) not in allowed:
            raise unknown_name(name.replace("_", " "), getattr(plant, name), allowed,
                               error=ScenarioError, field=f"plant_config.{name}")
    for name, driver in scenario.model_drivers.items():
        for f in dataclasses.fields(driver):
            value = getattr(driver, f.name)
            if isinstance(value, bool):
                continue
            _positive(value, f"model_drivers.{name}.{f.name}", "the driver's unit",
                      allow_zero=f.name != "force_limit")
    for name, camera in scenario.cameras.items():
        f = f"cameras.{name}"
        for size in ("width", "height"):
            if not getattr(camera, size) > 0:
                raise ScenarioError(f"must be > 0 [px], got {getattr(camera, size)}",
                                    field=f"{f}.{size}")
        fov = camera.focal
        for axis in ("x", "y"):
            value = getattr(fov, axis, None)
            if value is not None and isinstance(fov, CameraConfig.FovDegrees) and not (
                    _finite(value) and 0 < value < 180):
                raise ScenarioError(f"a field of view must be in (0, 180) [deg], got {value}",
                                    field=f"{f}.focal.{axis}")
            if value is not None and isinstance(fov, CameraConfig.FocalLength) and not (
                    _finite(value) and value > 0):
                raise ScenarioError(f"a focal length must be > 0 [px], got {value}",
                                    field=f"{f}.focal.{axis}")
        for near, far in (("clipping_near", "clipping_far"), ("z_near", "z_far")):
            a, b = getattr(camera, near), getattr(camera, far)
            if not (_finite([a, b]) and 0 < a < b):
                raise ScenarioError(f"need 0 < {near} < {far} [m], got {a} and {b}",
                                    field=f"{f}.{near}")
    if not (_finite(scenario.simulation_duration) and scenario.simulation_duration > 0):
        raise ScenarioError(f"must be a finite number > 0 [s], got "
                            f"{scenario.simulation_duration}", field="simulation_duration")
    sim = scenario.simulator_config
    _positive(sim.max_step_size, "simulator_config.max_step_size", "s")
    _positive(sim.target_realtime_rate, "simulator_config.target_realtime_rate", "1",
              allow_zero=True)
    if sim.use_error_control:
        _positive(sim.accuracy, "simulator_config.accuracy", "1")


# Two objects whose shapes overlap deeper than this interpenetrate [m]: the library's meshes are
# placed by their resting poses on the table, so objects that only touch overlap by rounding.
INTERPENETRATION_DEPTH = 0.002


def _footprint_points(scenario: Scenario, placement: ObjectPlacement) -> np.ndarray:
    """(V, 3) the object's mesh vertices in the table frame T, as placed [m]."""

    obj = get_object(placement.id)
    X_TO = placement_X_TO(placement, obj)
    yaw = np.deg2rad(placement.yaw)
    X_T = np.eye(4)
    X_T[:2, :2] = [[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]]
    X_T[:2, 3] = placement.xy
    X = X_T @ X_TO
    return mesh(obj)[0] @ X[:3, :3].T + X[:3, 3]


def _validate_geometry(scenario: Scenario) -> None:
    """Finite poses, the place target on the table, and objects that do not interpenetrate."""
    half = np.asarray(scenario.table_size) / 2
    for i, placement in enumerate(scenario.objects):
        if not _finite(placement.yaw):
            raise ScenarioError(f"yaw must be a finite number [deg], got {placement.yaw}",
                                field=f"objects[{i}].yaw")
    place = scenario.task.place_xy
    if len(place) != 2 or not _finite(place):
        raise ScenarioError(f"place_xy must be two finite numbers [m], got {place}",
                            field="task.place_xy")
    if np.any(np.abs(place) > half):
        raise ScenarioError(f"the place target {list(place)} is off the table (|x| ≤ {half[0]}, "
                            f"|y| ≤ {half[1]} in the table frame)", field="task.place_xy")
    if len(scenario.objects) < 2:
        return
    points = [_footprint_points(scenario, p) for p in scenario.objects]
    hulls = [ConvexHull(p) for p in points]
    for i in range(len(points)):
        for j in range(len(points)):
            if i == j:
                continue
            # Depth of each vertex of i inside j's convex hull (the facets' outward planes).
            eq = hulls[j].equations
            depth = -np.max(points[i] @ eq[:, :3].T + eq[:, 3], axis=1)
            if np.max(depth) > INTERPENETRATION_DEPTH:
                a, b = scenario.objects[i], scenario.objects[j]
                raise ScenarioError(
                    f"{a.instance_name} (objects[{i}]) and {b.instance_name} (objects[{j}]) "
                    f"interpenetrate by {np.max(depth) * 1000:.0f} mm; move them apart",
                    field=f"objects[{max(i, j)}].xy")


def place_surface(scenario: Scenario) -> SurfaceConfig | None:
    """The surface p&pOn places the object on (`task.place_on`, else the first), or None when the
    task is not p&pOn or the scenario has no surfaces (the object is then placed on the table at
    `place_xy`, and the task check fails saying so)."""
    if scenario.task.task != "p&pOn" or (not scenario.surfaces and not scenario.task.place_on):
        return None
    name = scenario.task.place_on or scenario.surfaces[0].name
    for surface in scenario.surfaces:
        if surface.name == name:
            return surface
    raise unknown_name("surface", name, [s.name for s in scenario.surfaces],
                       error=ScenarioError, field="task.place_on")


def _validate_surfaces(scenario: Scenario) -> None:
    """Surfaces: named uniquely, positive finite sizes, standing on the table top, under no
    object; p&pOn's `place_on` names one, pourOut's `pour_into` names another object."""
    half = np.asarray(scenario.table_size) / 2
    names = set()
    for i, surface in enumerate(scenario.surfaces):
        f = f"surfaces[{i}]"
        if not surface.name:
            raise ScenarioError("a surface needs a `name`", field=f"{f}.name")
        if surface.name in names:
            raise ScenarioError(f"two surfaces are named {surface.name!r}", field=f"{f}.name")
        names.add(surface.name)
        if len(surface.xy) != 2 or not _finite(surface.xy):
            raise ScenarioError(f"xy must be two finite numbers [m], got {surface.xy}",
                                field=f"{f}.xy")
        if len(surface.size) != 3 or not _finite(surface.size) or min(surface.size) <= 0:
            raise ScenarioError(f"size must be three finite numbers > 0 (x, y, height) [m], got "
                                f"{surface.size}", field=f"{f}.size")
        lo = np.asarray(surface.xy) - np.asarray(surface.size[:2]) / 2
        hi = np.asarray(surface.xy) + np.asarray(surface.size[:2]) / 2
        if np.any(lo < -half) or np.any(hi > half):
            raise ScenarioError(
                f"surface {surface.name!r} ({lo.round(3).tolist()} to {hi.round(3).tolist()}) "
                f"reaches off the table (|x| ≤ {half[0]}, |y| ≤ {half[1]} in the table frame)",
                field=f"{f}.xy")
        for j, placement in enumerate(scenario.objects):
            p = _footprint_points(scenario, placement)[:, :2]
            if np.all(p.max(0) > lo) and np.all(p.min(0) < hi):
                raise ScenarioError(
                    f"surface {surface.name!r} stands under {placement.instance_name} "
                    f"(objects[{j}]): objects stand on the table; move one of them",
                    field=f"{f}.xy")
    place_surface(scenario)
    into = scenario.task.pour_into
    if into:
        names = [p.instance_name for p in scenario.objects]
        if into not in names:
            raise unknown_name("object to pour into", into, names, error=ScenarioError,
                               field="task.pour_into")
        if scenario.objects and into == scenario.target_placement().instance_name:
            raise ScenarioError("the object poured into is the target itself",
                                field="task.pour_into")
def _validate_contents(scenario: Scenario) -> None:
    """The contents block, the dispenser, and (spheres) that each full container's cavity holds
    its spheres."""
    scenario.contents.validate()
    d = scenario.dispenser
    if d is not None:
        d.validate(scenario.table_size, scenario.contents)
        for i, placement in enumerate(scenario.objects):
            # The hopper's footprint (its width and walls) must stand clear above the object.
            p = _footprint_points(scenario, placement)
            under = np.all(np.abs(p[:, :2] - d.xy) <= d.width / 2 + DISPENSER_WALL, axis=1)
            if np.any(under) and p[under, 2].max() >= d.height:
                raise ScenarioError(
                    f"the dispenser's gate at height {d.height} m is inside "
                    f"{placement.instance_name} (objects[{i}]), which reaches "
                    f"{p[under, 2].max():.3f} m under it; raise it", field="dispenser.height")
    if scenario.contents.model != "spheres":
        return
    for i, placement in enumerate(scenario.objects):
        if placement.containment != "full":
            continue
        obj = get_object(placement.id)
        V, F = mesh(obj)[:2]
        try:
            container_sites(obj.id, V, F, scenario.contents)
        except ScenarioError as e:
            field = e.field if e.field == "contents.count" else f"objects[{i}].containment"
            raise ScenarioError(e.message, field=field) from None
