"""The simulated station: iiwa 14 + WSG 50, a table, library objects and RGB-D cameras.

    station = add_station(builder, scenario=scenario)  # into your own DiagramBuilder
    diagram = make_station(scenario)  # or a standalone diagram with exported ports

Contact is hydroelastic (`MultibodyPlantConfig`, SAP). The arm and the fingers are driven by the
plant's own PD controllers on their joint actuators (implicit in SAP, which allows a much larger
time step than an explicit inverse-dynamics loop); the WSG's finger force is limited through the
finger actuators' effort limits, which SAP respects. Gravity on the arm and gripper is
compensated (as the KUKA controller does for the arm and its configured payload); gravity acts on
everything else.

Cameras are `RgbdSensor`s added by Drake's `ApplyCameraConfig` from the scenario's `cameras`
(the key names the camera; `renderer_name` and `renderer_class` choose its render engine:
RenderEngineVtk, or RenderEngineGl where a display is available; anything else is a ScenarioError
before the station is built). No images are published. A sensor renders only when one of its image
ports is evaluated, so a stage that needs one image asks once, and the simulation itself never
renders.

A full container's contents are, by `contents.model`, the water's mass welded inside it ("mass")
or free compliant-hydroelastic spheres packed in its cavity ("spheres", `Station.contents`); a
`dispenser` adds a hopper of spheres above the table with a sliding gate (tg_drake.tasks.contents).
The spheres and the dispenser are drawn in Meshcat but not seen by the cameras.

Station ports (as exported by `make_station`; `add_station` returns the same ports by name):

- inputs: ``iiwa.desired_state`` (14: q, v), ``wsg.position`` (1: opening width [m]), and with a
  `dispenser` ``dispenser.open`` (1: > 0.5 opens its gate); with a receiver (a pass,
  tg_drake.receiver) ``receiver.mount`` (12) and ``receiver.position`` (1).
- outputs: ``iiwa.state`` (14), ``wsg.state`` (4), with a receiver ``receiver.state`` (4),
  ``body_poses``, ``contact_results``,
  ``query_object``, and per camera ``<camera>.rgb_image``, ``<camera>.depth_image``,
  ``<camera>.label_image``, ``<camera>.camera_pose`` (X_WC, a RigidTransform).
"""

from __future__ import annotations

import copy
import functools
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pydrake.common import MemoryFile
from pydrake.common.value import AbstractValue
from pydrake.geometry import (
    AddCompliantHydroelasticProperties,
    AddContactMaterial,
    AddRigidHydroelasticProperties,
    Box,
    CollisionFilterDeclaration,
    Convex,
    GeometryInstance,
    GeometrySet,
    InMemoryMesh,
    MakePhongIllustrationProperties,
    MakeRenderEngineGl,
    Mesh,
    PerceptionProperties,
    ProximityProperties,
    RenderEngineGlParams,
    Rgba,
    Role,
    SceneGraph,
    Sphere,
    kHasRenderEngineGl,
)
from pydrake.lcm import DrakeLcm
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.parsing import (
    AddModel,
    ModelDirective,
    ModelDirectives,
    Parser,
    ProcessModelDirectives,
)
from pydrake.multibody.plant import AddMultibodyPlant, CoulombFriction, MultibodyPlant
from pydrake.multibody.tree import (
    BodyIndex,
    JointActuatorIndex,
    ModelInstanceIndex,
    PdControllerGains,
    PrismaticJoint,
    SpatialInertia,
    UnitInertia,
)
from pydrake.systems.controllers import InverseDynamicsController
from pydrake.systems.framework import Diagram, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import MatrixGain
from pydrake.systems.sensors import ApplyCameraConfig, CameraConfig, CameraInfo, RgbdSensor

from tg_drake.errors import ModelError, ScenarioError, unknown_name
from tg_drake.models import make_parser
from tg_drake.objects import get_object, mesh, obj_text
from tg_drake.receiver import RECEIVER, add_receiver, connect_receiver, receiver_of
from tg_drake.robot import WSG_BODY, WSG_FINGER_JOINTS
from tg_drake.robot_plants import add_scenario_models, couple_fingers
from tg_drake.scenario import (
    InverseDynamicsDriver,
    JointPdDriver,
    ObjectPlacement,
    Scenario,
    WsgPdDriver,
    placement_X_TO,
    resolve_objects,
)
from tg_drake.support_hull import support_hull
from tg_drake.table import (
    FLOOR_MARGIN,
    FLOOR_THICKNESS,
    TABLE_HEIGHT,
    add_surfaces,
    add_table,
)
from tg_drake.tasks.contents import (
    DISPENSER_WALL,
    ContentsConfig,
    ContentsModel,
    DispenserConfig,
    container_sites,
    contents_wall,
    hopper_height,
    hopper_sites,
    jittered,
)

WATER_DENSITY = 1000.0  # [kg/m³] contents of a "full" container
NO_LCM = "memq://null"  # the LCM URL that publishes nothing: the station sends no messages


def placement_pose(scenario: Scenario, placement: ObjectPlacement) -> RigidTransform:
    """X_WO of a placed object: table frame · (xy, yaw on the table) · the library's resting
    X_TO (or its stable pose K: `resting: K`)."""
    X_TO = placement_X_TO(placement, get_object(placement.id))
    X_T_yaw = RigidTransform(RollPitchYaw(0, 0, np.deg2rad(placement.yaw)),
                             [placement.xy[0], placement.xy[1], 0.0])
    X_WT = scenario.X_WT.GetDeterministicValue()
    return X_WT @ X_T_yaw @ RigidTransform(X_TO)


@dataclass
class CameraHandles:
    sensor: RgbdSensor
    info: CameraInfo  # intrinsics of the depth camera
    X_PB: RigidTransform  # sensor body pose in its parent frame (the world)
    X_BC: RigidTransform  # depth camera in the sensor body


@dataclass
class Station:
    """What `add_station` added to a builder."""

    scenario: Scenario
    plant: MultibodyPlant
    scene_graph: SceneGraph
    instances: dict[str, ModelInstanceIndex]  # model instance name → index
    objects: dict[str, ModelInstanceIndex]  # placed library objects: instance name → index
    cameras: dict[str, CameraHandles]
    inputs: dict = field(default_factory=dict)  # port name → InputPort
    outputs: dict = field(default_factory=dict)  # port name → OutputPort
    # The spheres of each full container (contents.model: spheres) and of the dispenser.
    contents: list[ContentsModel] = field(default_factory=list)

    def object_body(self, name: str):
        bodies = self.plant.GetBodyIndices(self.objects[name])
        return self.plant.get_body(bodies[0])


class _CameraPose(LeafSystem):
    """Turns the sensor's body pose X_WB into the depth camera's pose X_WC = X_WB · X_BD."""

    def __init__(self, X_BC: RigidTransform):
        super().__init__()
        self._X_BC = X_BC
        self._X_WB = self.DeclareAbstractInputPort("X_WB", _rigid_transform_value())
        self.DeclareAbstractOutputPort("X_WC", _rigid_transform_value, self._calc,
                                       prerequisites_of_calc={self.all_input_ports_ticket()})

    def _calc(self, context, output):
        output.set_value(self._X_WB.Eval(context) @ self._X_BC)


def _rigid_transform_value():
    return AbstractValue.Make(RigidTransform())


def _actuators(plant: MultibodyPlant, instance: ModelInstanceIndex) -> list:
    """The joint actuators of a model instance (works before Finalize)."""
    actuators = [plant.get_joint_actuator(JointActuatorIndex(i))
                 for i in range(plant.num_actuators())]
    actuators = [a for a in actuators if a.model_instance() == instance]
    if not actuators:
        raise ModelError(f"model '{plant.GetModelInstanceName(instance)}' has no actuated joints")
    return actuators


def _apply_joint_pd(plant: MultibodyPlant, instance: ModelInstanceIndex, kp: float, kd: float):
    for actuator in _actuators(plant, instance):
        actuator.set_controller_gains(PdControllerGains(p=kp, d=kd))


def _add_objects(scenario: Scenario, plant: MultibodyPlant, parser: Parser,
                 contents: list[ContentsModel], visible: bool = False,
                 scene_graph: SceneGraph | None = None) -> dict[str, ModelInstanceIndex]:
    if not scenario.objects:
        return {}
    # User libraries and mesh entries (a validated scenario's paths are absolute; the import is
    # cached): get_object then knows every object, in this process too.
    resolve_objects(scenario)
    directives = [ModelDirective(add_model=AddModel(
        name=p.instance_name, file=get_object(p.id).sdf_url)) for p in scenario.objects]
    added = ProcessModelDirectives(ModelDirectives(directives=directives), parser)
    objects = {}
    for placement, info in zip(scenario.objects, added, strict=True):
        instance = info.model_instance
        objects[placement.instance_name] = instance
        body = plant.get_body(plant.GetBodyIndices(instance)[0])
        plant.SetDefaultFloatingBaseBodyPose(body, placement_pose(scenario, placement))
        if scene_graph is not None:
            add_support_hull(plant, scene_graph, body)
        if placement.containment == "full" and scenario.contents.model == "spheres":
            contents.append(_add_sphere_contents(plant, placement, get_object(placement.id),
                                                 placement_pose(scenario, placement),
                                                 scenario.contents, visible))
        elif placement.containment == "full":
            _add_contents(plant, instance, body, get_object(placement.id))
    return objects


SUPPORT_HULL = "support_hull"  # name of an object's table-contact geometry


@functools.lru_cache(maxsize=256)
def _support_hull_of(vertices: bytes) -> np.ndarray:
    return support_hull(np.frombuffer(vertices).reshape(-1, 3))


def add_support_hull(plant: MultibodyPlant, scene_graph: SceneGraph, body) -> None:
    """Registers `body`'s support hull (`tg_drake.support_hull`) as a collision geometry named
    SUPPORT_HULL with the proximity properties (rigid hydroelastic, friction) of its first mesh,
    built from the convex hulls of all its mesh and convex collision geometries (before
    Finalize; `support_hulls_touch_only_the_table` filters the pairs after it). A body without
    such geometry gets none."""
    inspector = scene_graph.model_inspector()
    points, properties = [], None
    for g in plant.GetCollisionGeometriesForBody(body):
        shape = inspector.GetShape(g)
        if not isinstance(shape, Mesh | Convex):
            continue
        hull = shape.GetConvexHull()
        V = np.array([hull.vertex(i) for i in range(hull.num_vertices())])
        points.append(inspector.GetPoseInFrame(g).multiply(V.T).T)
        properties = properties or ProximityProperties(inspector.GetProximityProperties(g))
    if not points:
        return
    P = _support_hull_of(np.ascontiguousarray(np.vstack(points), float).tobytes())
    shape = Convex(np.asarray(P, float).T.copy(), SUPPORT_HULL)
    plant.RegisterCollisionGeometry(body, RigidTransform(), shape, SUPPORT_HULL, properties)


def support_hulls_touch_only_the_table(plant: MultibodyPlant, scene_graph: SceneGraph,
                                       table: ModelInstanceIndex, objects) -> None:
    """Collision filters (after Finalize): each object's support hull touches only the table and
    its surfaces, and its other geometry everything but them."""
    inspector = scene_graph.model_inspector()
    # The object's own body (the first of its model instance; a full container's spheres are
    # bodies of the instance too and keep the table).
    own = {g for i in objects
           for g in plant.GetCollisionGeometriesForBody(plant.get_body(plant.GetBodyIndices(i)[0]))}
    support = {g for g in own if inspector.GetName(g).endswith(SUPPORT_HULL)}
    if not support:
        return
    table_geometries = {g for b in plant.GetBodyIndices(table)
                        for g in plant.GetCollisionGeometriesForBody(plant.get_body(b))}
    meshes = own - support
    others = set(inspector.GetAllGeometryIds(Role.kProximity)) - table_geometries
    manager = scene_graph.collision_filter_manager()
    manager.Apply(CollisionFilterDeclaration().ExcludeBetween(
        GeometrySet(list(support)), GeometrySet(list(others))))
    if meshes:
        manager.Apply(CollisionFilterDeclaration().ExcludeBetween(
            GeometrySet(list(meshes)), GeometrySet(list(table_geometries))))


def contents_cylinder(obj) -> tuple[float, float, np.ndarray]:
    """(radius, height, p_OC): the water of a full container as a cylinder of the cavity's volume,
    of the inner diameter, standing on the container's base (O: origin at the bottom centre,
    z up)."""
    d = obj.dimensions
    radius = d["diameter"] / 2 - d.get("wall", 0.0)
    height = obj.cavity_volume / (np.pi * radius**2)
    return radius, height, np.array([0.0, 0.0, d.get("base", d.get("wall", 0.0)) + height / 2])


def _add_contents(plant: MultibodyPlant, instance, body, obj) -> None:
    """A "full" container: water filling its cavity, as a solid cylinder welded inside it (mass
    and inertia only; the water has no geometry)."""
    radius, height, p_OC = contents_cylinder(obj)
    mass = WATER_DENSITY * obj.cavity_volume
    M = SpatialInertia(mass=mass, p_PScm_E=np.zeros(3),
                       G_SP_E=UnitInertia.SolidCylinder(radius, height, [0, 0, 1]))
    contents = plant.AddRigidBody(f"{body.name()}_contents", instance, M)
    plant.WeldFrames(body.body_frame(), contents.body_frame(), RigidTransform(p_OC))


SPHERE_COLOR = (0.2, 0.45, 0.9, 1.0)  # RGBA of the contents' spheres (Meshcat)
DISPENSER_COLOR = (0.6, 0.6, 0.65, 0.5)  # RGBA of the hopper and its gate
GATE_GAP = 0.001  # [m] between the walls' bottom and the gate's top, so the gate slides free
GATE_MASS = 0.2  # [kg]
GATE_KP = 400.0  # [N/m] PD gains of the gate's slide (it opens by one width in ~0.3 s)
GATE_KD = 40.0  # [N·s/m]
GATE_FORCE = 50.0  # [N] effort limit of the gate's actuator


def _illustration_only(shape, name: str, X_BG: RigidTransform, rgba, visible: bool
                       ) -> GeometryInstance:
    """Visual geometry for Meshcat; the cameras see it only when `visible`."""
    instance = GeometryInstance(X_BG, shape, name)
    instance.set_illustration_properties(MakePhongIllustrationProperties(np.asarray(rgba)))
    if visible:
        perception = PerceptionProperties()
        perception.AddProperty("phong", "diffuse", Rgba(*rgba))
        instance.set_perception_properties(perception)
    return instance


def add_spheres(plant: MultibodyPlant, instance: ModelInstanceIndex, prefix: str,
                p_W: np.ndarray, radius: float, mass: float, config: ContentsConfig,
                visible: bool = False) -> tuple[int, ...]:
    """Free compliant-hydroelastic spheres of `radius` [m] and `mass` [kg] each at the world
    positions p_W (n, 3) (moved by `config.start_jitter`: `tasks.contents.jittered`), before
    Finalize; returns their body indices."""
    p_W = jittered(p_W, config.start_jitter, config.start_seed)
    proximity = ProximityProperties()
    AddContactMaterial(dissipation=config.dissipation,
                       friction=CoulombFriction(config.friction, config.friction),
                       properties=proximity)
    AddCompliantHydroelasticProperties(config.resolution_hint, config.modulus, proximity)
    M = SpatialInertia.SolidSphereWithMass(mass, radius)
    bodies = []
    for k, p in enumerate(np.asarray(p_W, float)):
        body = plant.AddRigidBody(f"{prefix}_{k}", instance, M)
        plant.RegisterCollisionGeometry(body, RigidTransform(), Sphere(radius), "collision",
                                        proximity)
        plant.RegisterVisualGeometry(body, _illustration_only(
            Sphere(radius), f"{prefix}_{k}_visual", RigidTransform(), SPHERE_COLOR, visible))
        plant.SetDefaultFloatingBaseBodyPose(body, RigidTransform(p))
        bodies.append(int(body.index()))
    return tuple(bodies)


CONTENTS_WALL = "contents_wall"  # name of an object's simplified surface for the spheres


def add_contents_wall(plant: MultibodyPlant, scene_graph: SceneGraph, body, obj) -> dict:
    """Before Finalize, in a scene with sphere contents: the library object `obj`'s collision
    mesh on `body` gets a simplified copy (`tasks.contents.contents_wall`, within WALL_TOLERANCE
    of it) named CONTENTS_WALL, with the same pose and proximity properties. Returns {the copy's
    id: the original's name}; `spheres_touch_walls` then lets the spheres touch the copy only,
    and everything else the original only. Convex pieces (imported objects) are left as they
    are."""
    inspector = scene_graph.model_inspector()
    walls = {}
    for g in plant.GetCollisionGeometriesForBody(body):
        shape = inspector.GetShape(g)
        if not (isinstance(shape, Mesh) and shape.source().is_path()
                and Path(shape.source().path()).resolve() == obj.mesh_path.resolve()):
            continue
        V, F = mesh(obj)[:2]
        Vw, Fw = contents_wall(V * shape.scale(), F)
        if len(Fw) >= len(F):
            continue
        # (the plant scopes the name by the model instance, as the original's already is)
        name = f"{inspector.GetName(g).split('::')[-1]}_{CONTENTS_WALL}"
        text = obj_text(Vw, Fw, name=name, comment="the surface the spheres touch (metres, O)")
        wall = Mesh(InMemoryMesh(mesh_file=MemoryFile(text, ".obj", name)))
        walls[plant.RegisterCollisionGeometry(
            body, inspector.GetPoseInFrame(g), wall, name,
            ProximityProperties(inspector.GetProximityProperties(g)))] = inspector.GetName(g)
    return walls


def sphere_geometries(plant: MultibodyPlant, contents: list[ContentsModel]) -> list:
    """The proximity geometry ids of every sphere of `contents` (after Finalize)."""
    return [g for m in contents for b in m.bodies
            for g in plant.GetCollisionGeometriesForBody(plant.get_body(BodyIndex(b)))]


def spheres_touch_walls(plant: MultibodyPlant, scene_graph: SceneGraph,
                        contents: list[ContentsModel], walls: dict) -> None:
    """Collision filters (after Finalize): the spheres touch each object's simplified wall and
    not its original mesh; every other geometry the original and not the wall."""
    inspector = scene_graph.model_inspector()
    spheres = set(sphere_geometries(plant, contents))
    # (the originals by name: ids taken before Finalize are not kept)
    originals = [inspector.GetGeometryIdByName(inspector.GetFrameId(w), Role.kProximity, name)
                 for w, name in walls.items()]
    others = set(inspector.GetAllGeometryIds(Role.kProximity)) - spheres - set(walls)
    manager = scene_graph.collision_filter_manager()
    manager.Apply(CollisionFilterDeclaration().ExcludeBetween(
        GeometrySet(list(spheres)), GeometrySet(originals)))
    manager.Apply(CollisionFilterDeclaration().ExcludeBetween(
        GeometrySet(list(walls)), GeometrySet(list(others | set(walls)))))


CONTENTS_FLOOR = "contents_floor"  # name of the floor under the table, for the spheres
FLOOR_FRICTION = 0.5  # [1] Coulomb friction of the floor (static = dynamic)
FLOOR_DISSIPATION = 5.0  # [s/m] Hunt–Crossley dissipation of the floor


def add_contents_floor(plant: MultibodyPlant, X_WT: RigidTransform, table_size):
    """Before Finalize, in a scene with sphere contents: the floor TABLE_HEIGHT below the table
    top, a rigid-hydroelastic slab on the world (FLOOR_THICKNESS thick, reaching FLOOR_MARGIN
    past each edge of the table; a sphere is compliant: their contact is a surface). A sphere
    that leaves the table (spilled, or now and then shot out of a pinch between two rigid
    walls) lands there instead of falling without end, and `count_contents` counts it on the
    floor (one that leaves even the floor is frozen as a stray: tg_drake.simulation.sleep).
    Returns its geometry id; `floor_touches_only_spheres` filters the rest."""
    props = ProximityProperties()
    AddContactMaterial(dissipation=FLOOR_DISSIPATION,
                       friction=CoulombFriction(FLOOR_FRICTION, FLOOR_FRICTION), properties=props)
    AddRigidHydroelasticProperties(props)
    size = [float(v) + 2 * FLOOR_MARGIN for v in table_size] + [FLOOR_THICKNESS]
    X_TF = RigidTransform([0.0, 0.0, -TABLE_HEIGHT - 0.5 * FLOOR_THICKNESS])
    return plant.RegisterCollisionGeometry(plant.world_body(), X_WT @ X_TF, Box(*size),
                                           CONTENTS_FLOOR, props)


def floor_touches_only_spheres(plant: MultibodyPlant, scene_graph: SceneGraph,
                               contents: list[ContentsModel], floor) -> None:
    """Collision filters (after Finalize): the contents' floor touches the spheres only (an
    object that falls off the table falls as it did before)."""
    others = set(scene_graph.model_inspector().GetAllGeometryIds(Role.kProximity))
    others -= set(sphere_geometries(plant, contents)) | {floor}
    scene_graph.collision_filter_manager().Apply(CollisionFilterDeclaration().ExcludeBetween(
        GeometrySet([floor]), GeometrySet(list(others))))


def exclude_mutual_contact(plant: MultibodyPlant, scene_graph: SceneGraph,
                           contents: list[ContentsModel]) -> None:
    """Filters contact between any two spheres (after Finalize)."""
    scene_graph.collision_filter_manager().Apply(
        CollisionFilterDeclaration().ExcludeWithin(GeometrySet(sphere_geometries(plant,
                                                                                 contents))))


def _add_sphere_contents(plant: MultibodyPlant, placement: ObjectPlacement, obj,
                         X_WO: RigidTransform, config: ContentsConfig,
                         visible: bool = False) -> ContentsModel:
    """A "full" container's water as free spheres packed in its cavity, of the water's total
    mass (WATER_DENSITY × cavity volume), in a model instance `<name>_contents`."""
    V, F = mesh(obj)[:2]
    p_O = container_sites(obj.id, V, F, config)
    name = placement.instance_name
    instance = plant.AddModelInstance(f"{name}_contents")
    mass = WATER_DENSITY * obj.cavity_volume / len(p_O)
    p_W = p_O @ X_WO.rotation().matrix().T + X_WO.translation()
    bodies = add_spheres(plant, instance, f"{name}_sphere", p_W, config.radius, mass, config,
                         visible)
    return ContentsModel(name=name, bodies=bodies, radius=config.radius)


def dispenser_frame(scenario: Scenario) -> RigidTransform:
    """X_WH: the hopper frame H, at the centre of the gate's top, axes of the table frame."""
    d = scenario.dispenser
    return scenario.X_WT.GetDeterministicValue() @ RigidTransform([d.xy[0], d.xy[1], d.height])


def _add_dispenser(plant: MultibodyPlant, scenario: Scenario, visible: bool = False
                   ) -> tuple[ContentsModel, object]:
    """The dispenser: a square hopper welded above the table, its spheres, and a gate under it on
    a PD-driven slide along the table's x (closed at 0, open at one width and a wall). Returns the
    spheres and the gate joint."""
    d: DispenserConfig = scenario.dispenser
    radius = d.sphere_radius(scenario.contents)
    X_WH = dispenser_frame(scenario)
    instance = plant.AddModelInstance("dispenser")
    t, w = DISPENSER_WALL, d.width
    h = hopper_height(d, radius)
    hopper = plant.AddRigidBody("dispenser_hopper", instance,
                                SpatialInertia.SolidBoxWithMass(1.0, w, w, h))
    plant.WeldFrames(plant.world_frame(), hopper.body_frame(), X_WH)
    rigid = ProximityProperties()
    AddContactMaterial(friction=CoulombFriction(0.3, 0.3), properties=rigid)
    AddRigidHydroelasticProperties(rigid)
    z = GATE_GAP + h / 2
    for k, (x, y, sx, sy) in enumerate((((w + t) / 2, 0, t, w + 2 * t), (-(w + t) / 2, 0, t,
                                        w + 2 * t), (0, (w + t) / 2, w, t), (0, -(w + t) / 2,
                                                                             w, t))):
        X = RigidTransform([x, y, z])
        plant.RegisterCollisionGeometry(hopper, X, Box(sx, sy, h), f"wall_{k}", rigid)
        plant.RegisterVisualGeometry(hopper, _illustration_only(
            Box(sx, sy, h), f"wall_{k}_visual", X, DISPENSER_COLOR, visible))
    gate = plant.AddRigidBody("dispenser_gate", instance, SpatialInertia.SolidBoxWithMass(
        GATE_MASS, w + 2 * t, w + 2 * t, t))
    X = RigidTransform([0, 0, -t / 2])
    plant.RegisterCollisionGeometry(gate, X, Box(w + 2 * t, w + 2 * t, t), "gate", rigid)
    plant.RegisterVisualGeometry(gate, _illustration_only(
        Box(w + 2 * t, w + 2 * t, t), "gate_visual", X, DISPENSER_COLOR, visible))
    joint = plant.AddJoint(PrismaticJoint("dispenser_gate_slide", hopper.body_frame(),
                                          gate.body_frame(), [1.0, 0.0, 0.0]))
    actuator = plant.AddJointActuator("dispenser_gate_actuator", joint, GATE_FORCE)
    actuator.set_controller_gains(PdControllerGains(p=GATE_KP, d=GATE_KD))
    spheres = plant.AddModelInstance("dispenser_contents")
    p_H = hopper_sites(d, radius)
    p_W = p_H @ X_WH.rotation().matrix().T + X_WH.translation()
    mass = WATER_DENSITY * 4.0 / 3.0 * np.pi * radius**3
    bodies = add_spheres(plant, spheres, "dispenser_sphere", p_W, radius, mass,
                         scenario.contents, visible)
    return ContentsModel(name="dispenser", bodies=bodies, radius=radius), joint


def gate_travel(config: DispenserConfig) -> float:
    """[m] of the gate's slide from closed to open: the hopper's width and both walls."""
    return config.width + 2 * DISPENSER_WALL + 0.01


class DispenserCommand(LeafSystem):
    """`open` (1-vector; > 0.5 opens) → the gate's desired state (position along the slide [m],
    velocity 0)."""

    def __init__(self, travel: float):
        super().__init__()
        self._travel = travel
        self.DeclareVectorInputPort("open", 1)
        self.DeclareVectorOutputPort("desired_state", 2, self._calc)

    def _calc(self, context, output):
        is_open = self.get_input_port().Eval(context)[0] > 0.5
        output.SetFromVector([self._travel if is_open else 0.0, 0.0])


def add_station(builder: DiagramBuilder, *, scenario: Scenario,
                contents_visible: bool = False) -> Station:
    """Adds the plant, scene graph, drivers and cameras of `scenario` to `builder`. The cameras
    see the contents' spheres and the dispenser only with `contents_visible` (the pictures'
    station, tg_drake.render; never perception's)."""
    _check_renderers(scenario)
    # Plant and scene graph, hydroelastic contact with SAP.
    plant, scene_graph = AddMultibodyPlant(scenario.plant_config, builder)
    parser = make_parser(plant)

    # Robot and gripper from the directives, the table from table_size and X_WT; library objects
    # from the `objects` block.
    try:
        added = ProcessModelDirectives(ModelDirectives(directives=scenario.directives), parser)
    except RuntimeError as e:
        raise ModelError(f"could not load the scenario's directives: {e}") from None
    instances = {plant.GetModelInstanceName(i.model_instance): i.model_instance for i in added}
    if plant.HasModelInstanceNamed("table"):
        raise ScenarioError("the directives add a model named 'table'; the station adds the table "
                            "itself, from table_size and X_WT: remove that directive",
                            field="directives")
    X_WT = scenario.X_WT.GetDeterministicValue()
    instances["table"] = add_table(plant, scenario.table_size, X_WT)
    add_surfaces(plant, instances["table"], scenario.surfaces)
    contents: list[ContentsModel] = []
    objects = _add_objects(scenario, plant, parser, contents, contents_visible, scene_graph)
    instances.update(objects)
    if scenario.dispenser is not None:
        dispensed, _ = _add_dispenser(plant, scenario, contents_visible)
        contents.append(dispensed)
    if receiver_of(scenario) is not None:  # a pass: the second WSG (tg_drake.receiver)
        instances[RECEIVER] = add_receiver(plant, parser, scenario)
    # With spheres, the floor the table stands on, for them (see add_contents_floor).
    floor = add_contents_floor(plant, X_WT, scenario.table_size) if contents else None
    walls = {}  # with spheres, each object's simplified wall for them
    for placement in scenario.objects if contents else ():
        body = plant.get_body(plant.GetBodyIndices(objects[placement.instance_name])[0])
        walls.update(add_contents_wall(plant, scene_graph, body, get_object(placement.id)))

    # Drivers: PD control on the joint actuators (desired state enters the plant).
    for name, driver in scenario.model_drivers.items():
        if name not in instances:
            raise ScenarioError(f"model_drivers names '{name}', which the directives do not add; "
                                f"models: {', '.join(instances)}", field="model_drivers")
        instance = instances[name]
        if isinstance(driver, InverseDynamicsDriver):
            continue  # its controller is added after Finalize
        _apply_joint_pd(plant, instance, driver.kp, driver.kd)
        if isinstance(driver, WsgPdDriver):
            for actuator in _actuators(plant, instance):
                actuator.set_effort_limit(driver.force_limit)
            if driver.coupled:
                couple_fingers(plant, instance)
        if isinstance(driver, JointPdDriver) and not driver.gravity_compensation:
            continue
        plant.set_gravity_enabled(instance, False)
    plant.Finalize()

    station = Station(scenario=scenario, plant=plant, scene_graph=scene_graph,
                      instances=instances, objects=objects, cameras={}, contents=contents)
    support_hulls_touch_only_the_table(plant, scene_graph, instances["table"],
                                       list(objects.values()))
    if walls:
        spheres_touch_walls(plant, scene_graph, contents, walls)
    if contents and not scenario.contents.mutual:
        exclude_mutual_contact(plant, scene_graph, contents)
    if floor is not None:
        floor_touches_only_spheres(plant, scene_graph, contents, floor)
    if scenario.dispenser is not None:
        command = builder.AddNamedSystem("dispenser_command",
                                         DispenserCommand(gate_travel(scenario.dispenser)))
        builder.Connect(command.get_output_port(), plant.get_desired_state_input_port(
            plant.GetModelInstanceByName("dispenser")))
        station.inputs["dispenser.open"] = command.get_input_port()
    if RECEIVER in instances:
        connect_receiver(builder, station)

    # Ports of the arm and the gripper.
    if "iiwa" in instances:
        iiwa = instances["iiwa"]
        driver = scenario.model_drivers.get("iiwa")
        if isinstance(driver, InverseDynamicsDriver):
            controller = _add_inverse_dynamics(builder, scenario, plant, iiwa, driver)
            station.inputs["iiwa.desired_state"] = controller.get_input_port_desired_state()
        else:
            station.inputs["iiwa.desired_state"] = plant.get_desired_state_input_port(iiwa)
        station.outputs["iiwa.state"] = plant.get_state_output_port(iiwa)
    if "wsg" in instances:
        # Opening width w → finger joint positions (−w/2, +w/2), zero velocities.
        to_state = builder.AddNamedSystem("wsg_width_to_desired_state",
                                          MatrixGain(np.array([[-0.5], [0.5], [0.0], [0.0]])))
        builder.Connect(to_state.get_output_port(),
                        plant.get_desired_state_input_port(instances["wsg"]))
        station.inputs["wsg.position"] = to_state.get_input_port()
        station.outputs["wsg.state"] = plant.get_state_output_port(instances["wsg"])
    station.outputs["body_poses"] = plant.get_body_poses_output_port()
    station.outputs["contact_results"] = plant.get_contact_results_output_port()
    station.outputs["query_object"] = scene_graph.get_query_output_port()

    # Cameras: Drake's ApplyCameraConfig adds each RgbdSensor (and its renderer, by the config's
    # renderer_name and renderer_class); a sensor renders only when an image port is asked.
    for name, config in scenario.cameras.items():
        _add_camera(builder, station, name, config)
    return station


# The renderer classes the station can build here (CameraConfig.renderer_class by name; the
# parameter structs of the same engines are accepted too).
RENDERER_CLASSES = ("RenderEngineVtk", "RenderEngineGl")


@functools.cache
def _gl_unavailable() -> str | None:
    """Why RenderEngineGl cannot render on this machine (no display, no GL build), or None."""
    if not kHasRenderEngineGl:
        return "this Drake build has no RenderEngineGl"
    try:
        MakeRenderEngineGl(RenderEngineGlParams())
    except RuntimeError as e:
        return " ".join(str(e).split())
    return None


def _renderer_class_name(renderer_class) -> str:
    """The engine a CameraConfig.renderer_class asks for: a class name ("" = Drake's default,
    RenderEngineVtk) or the class of its parameter struct."""
    if isinstance(renderer_class, str):
        return renderer_class or "RenderEngineVtk"
    return type(renderer_class).__name__.removesuffix("Params")


def _check_renderers(scenario: Scenario) -> None:
    """Rejects, before anything is built, a camera whose renderer_class this machine cannot render
    with, naming the field and the classes that work here."""
    for name, config in scenario.cameras.items():
        where = f"cameras.{name}.renderer_class"
        usable = [c for c in RENDERER_CLASSES if c != "RenderEngineGl" or _gl_unavailable() is None]
        engine = _renderer_class_name(config.renderer_class)
        if engine == "RenderEngineGl" and _gl_unavailable() is not None:
            raise ScenarioError(f"RenderEngineGl cannot render on this machine "
                                f"({_gl_unavailable()}); allowed here: {', '.join(usable)}",
                                field=where)
        if engine == "RenderEngineGltfClient":
            raise ScenarioError("RenderEngineGltfClient renders on a glTF server, which the "
                                f"station does not run; allowed here: {', '.join(usable)}",
                                field=where)
        if engine not in RENDERER_CLASSES:
            raise unknown_name("renderer class", engine, usable, error=ScenarioError,
                               field=where)


def _add_camera(builder: DiagramBuilder, station: Station, name: str, config: CameraConfig
                ) -> None:
    """One camera through ApplyCameraConfig (no image publishing: LCM is off), and its ports."""
    if not (config.rgb or config.depth):
        return  # ApplyCameraConfig adds no sensor for a camera with neither image
    config = copy.deepcopy(config)
    config.name = name  # the key in `cameras` names the camera (and its ports)
    try:
        ApplyCameraConfig(config=config, builder=builder, plant=station.plant,
                          scene_graph=station.scene_graph, lcm=DrakeLcm(NO_LCM))
    except RuntimeError as e:
        raise ScenarioError(" ".join(str(e).split()), field=f"cameras.{name}") from None
    sensor = builder.GetMutableSubsystemByName(f"rgbd_sensor_{name}")
    depth_camera = sensor.default_depth_render_camera()
    X_BC = depth_camera.core().sensor_pose_in_camera_body()
    pose = builder.AddNamedSystem(f"camera_pose_{name}", _CameraPose(X_BC))
    builder.Connect(sensor.body_pose_in_world_output_port(), pose.get_input_port())
    station.cameras[name] = CameraHandles(sensor=sensor, info=depth_camera.core().intrinsics(),
                                          X_PB=sensor.default_X_PB(), X_BC=X_BC)
    station.outputs[f"{name}.rgb_image"] = sensor.color_image_output_port()
    station.outputs[f"{name}.depth_image"] = sensor.depth_image_32F_output_port()
    station.outputs[f"{name}.label_image"] = sensor.label_image_output_port()
    station.outputs[f"{name}.camera_pose"] = pose.get_output_port()


def _add_inverse_dynamics(builder, scenario, plant, iiwa, driver):
    """Drake's explicit inverse-dynamics controller for the arm, the gripper as its payload."""
    control_plant = MultibodyPlant(time_step=0.0)
    add_scenario_models(control_plant, scenario, ("iiwa", "wsg"))
    wsg = control_plant.GetModelInstanceByName("wsg")
    for joint in WSG_FINGER_JOINTS:
        # The fingers' mass rides along as payload; their joints are locked for the controller.
        j = control_plant.GetJointByName(joint, wsg)
        parent, child = j.frame_on_parent(), j.frame_on_child()
        control_plant.RemoveJointActuator(control_plant.GetJointActuatorByName(joint, wsg))
        control_plant.RemoveJoint(j)
        control_plant.WeldFrames(parent, child)
    control_plant.Finalize()
    n = control_plant.num_positions()
    controller = builder.AddNamedSystem("iiwa_inverse_dynamics", InverseDynamicsController(
        control_plant, kp=[driver.kp] * n, ki=[driver.ki] * n, kd=[driver.kd] * n,
        has_reference_acceleration=False))
    controller.set_name("iiwa_inverse_dynamics")
    builder.Connect(plant.get_state_output_port(iiwa), controller.get_input_port_estimated_state())
    builder.Connect(controller.get_output_port_control(), plant.get_actuation_input_port(iiwa))
    return controller


def make_station(scenario: Scenario, *, contents_visible: bool = False
                 ) -> tuple[Diagram, Station]:
    """A standalone station diagram with every station port exported under its name."""
    builder = DiagramBuilder()
    station = add_station(builder, scenario=scenario, contents_visible=contents_visible)
    for name, port in station.inputs.items():
        builder.ExportInput(port, name)
    for name, port in station.outputs.items():
        builder.ExportOutput(port, name)
    diagram = builder.Build()
    diagram.set_name("station")
    return diagram, station


def flange_pose(plant: MultibodyPlant, plant_context) -> RigidTransform:
    """X_W7: pose of the iiwa's link 7 (the flange is 0.045 m further along its z)."""
    return plant.GetFrameByName("iiwa_link_7").CalcPoseInWorld(plant_context)


def gripper_pose(plant: MultibodyPlant, plant_context) -> RigidTransform:
    """X_WG: pose of the WSG body frame G."""
    return plant.GetFrameByName(WSG_BODY, plant.GetModelInstanceByName("wsg")).CalcPoseInWorld(
        plant_context)


def rotation_from_axes(x_W, y_W) -> RotationMatrix:
    """A rotation whose x and y axes are (the orthonormalised) x_W and y_W."""
    x = np.asarray(x_W, float)
    x = x / np.linalg.norm(x)
    y = np.asarray(y_W, float) - x * np.dot(x, y_W)
    y = y / np.linalg.norm(y)
    return RotationMatrix(np.column_stack([x, y, np.cross(x, y)]))
