"""The full pipeline as one Drake diagram, built from a scenario.

    builder = DiagramBuilder()
    pipeline = add_pipeline(builder, scenario=scenario)   # station + every stage, wired
    diagram = builder.Build()

The same builder is the public way to compose our systems with your own: `add_pipeline` returns
every system it added (`pipeline.perception`, `.prior`, `.logic`, `.scoring`, `.feasibility`,
`.planner`, `.supervisor` and the `station`), so you can add systems of yours to the same
builder and connect them to any port — or call `add_station` alone and wire only the stages you
want.

Wiring (docs/design.md, "The diagram"):

    station camera depth, camera pose ─▶ perception ─▶ target ─▶ scene_description
        (latched: perceived at initialization and on a new perception_request, never live)
    scene_description ─▶ prior ─▶ category_prior
    scene_description, category_prior, task, collisions ─▶ logic ─▶ grasp_semantics
    scene_description, grasp_semantics ─▶ scoring ─▶ ranked_grasps (ports: scored_grasps; the
        hypotheses turned into the poses that may be executed, each scored by the DGI)
    scene_description, grasp_semantics, ranked_grasps ─▶ feasibility ─▶ ranked_grasps (those
        poses as they are, with collisions and P(hold))
    scene_description, ranked_grasps, iiwa.state, plan_request ─▶ planner ─▶ iiwa.desired_state,
        wsg.position, plan_status
    scene_description, grasp_semantics, ranked_grasps, plan_status, wsg.state, body_poses,
        contact_results, perception_status ─▶ supervisor ─▶ collisions (─▶ logic), plan_request
        (─▶ planner), outcome, perception_request (─▶ perception: look again after a
        place-and-regrasp leg), target_xy (─▶ target)
    a pass (tg_drake.receiver): grasp_semantics ─▶ planner (the receiver's part); plan_status,
        body_poses ─▶ receiver_driver ─▶ receiver.mount, receiver.position; receiver.state ─▶
        supervisor

The supervisor closes the loop (unreachable parts become collision evidence, the logic's veto is
checked after every re-query) and judges the execution: simulate until
``pipeline.ports["outcome"]`` is final.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import DiagramBuilder, EventStatus, LeafSystem

from tg_drake.errors import ScenarioError, unknown_name
from tg_drake.grasping.model import load_model
from tg_drake.objects import box_centre, get_object, mesh, sample_surface
from tg_drake.planning.task_motion import dispenser_obstacle, surfaces_in_world, task_placing
from tg_drake.receiver import ReceiverDriver, Surface, handover_of
from tg_drake.scenario import DepthPerception, PipelineConfig, Scenario, place_surface
from tg_drake.station import DISPENSER_WALL, Station, add_station, dispenser_frame, placement_pose
from tg_drake.systems.depth_noise import DepthNoise
from tg_drake.systems.dgi_system import DgiScoringSystem
from tg_drake.systems.feasibility_system import GraspFeasibility
from tg_drake.systems.grasp_planner import GraspPlanner
from tg_drake.systems.kernel_prior_system import KernelPriorSystem
from tg_drake.systems.logic_system import LogicQuerySystem, TaskSource
from tg_drake.systems.perception_system import (
    REQUEST_OFFSET,
    REQUEST_PERIOD,
    GroundTruthPerception,
    PerceptionSystem,
)
from tg_drake.systems.supervisor import MonitorModel, Supervisor
from tg_drake.table import surface_body_name
from tg_drake.targeting import select_target
from tg_drake.tasks.contents import hopper_height
from tg_drake.tasks.judge import contents_counter
from tg_drake.types import SceneDescription

# [m] the spacing of the points on the target's surface the pass's receiver compares shapes with
# (tg_drake.receiver.seen_correction): under its see_tolerance's reach (3 mm) over a few points.
RECEIVER_SURFACE_SPACING = 0.005


class TargetSelector(LeafSystem):
    """Marks the task's target among the perceived objects (`tg_drake.targeting.select_target`).

    .. pydrake_system::

        name: TargetSelector
        input_ports:
        - scene_description
        - target_xy (optional)
        output_ports:
        - scene_description

    ``target_xy`` (tuple: () or a world xy [m], the supervisor's): where a place-and-regrasp leg
    put the target. The hint is latched state: a periodic event at perception's looks
    (`REQUEST_PERIOD`, `REQUEST_OFFSET`: off the plant's step grid) replaces it by a new
    ``target_xy``, so the output, and every cache downstream, depends on the scene and the latch
    only, never on the supervisor's changing state.
    """

    def __init__(self, p_W_hint):
        super().__init__()
        model = AbstractValue.Make(SceneDescription(objects=[], X_WT=np.eye(4)))
        self._in = self.DeclareAbstractInputPort("scene_description", model)
        self._moved = self.DeclareAbstractInputPort("target_xy", AbstractValue.Make(()))
        self._hint = self.DeclareAbstractState(AbstractValue.Make(
            tuple(float(v) for v in np.asarray(p_W_hint, float)[:2])))
        self.DeclarePeriodicUnrestrictedUpdateEvent(REQUEST_PERIOD, REQUEST_OFFSET, self._look)
        self.DeclareAbstractOutputPort(
            "scene_description", lambda: AbstractValue.Make(
                SceneDescription(objects=[], X_WT=np.eye(4))), self._calc,
            prerequisites_of_calc={self.input_port_ticket(self._in.get_index()),
                                   self.abstract_state_ticket(self._hint)})

    def _look(self, context, state):
        if not self._moved.HasValue(context):
            return EventStatus.DidNothing()
        moved = tuple(float(v) for v in self._moved.Eval(context))
        if not moved or moved == context.get_abstract_state(self._hint).get_value():
            return EventStatus.DidNothing()
        state.get_mutable_abstract_state(self._hint).set_value(moved)
        return EventStatus.Succeeded()

    def _calc(self, context, output):
        hint = np.asarray(context.get_abstract_state(self._hint).get_value(), float)
        output.set_value(select_target(self._in.Eval(context), hint))


@dataclass
class Pipeline:
    station: Station
    perception: LeafSystem
    target: TargetSelector
    prior: LeafSystem
    logic: LeafSystem
    scoring: LeafSystem
    feasibility: LeafSystem
    planner: LeafSystem
    supervisor: LeafSystem
    task: LeafSystem
    config: PipelineConfig
    ports: dict = field(default_factory=dict)  # stage output ports by name


def _part_vertices(object_id: str) -> tuple:
    """(vertices (V, 3) [m], part labels (V,)) of a library object's mesh: where the supervisor
    measures which part the receiver of a pass holds."""
    V, _, L = mesh(object_id)
    return np.asarray(V, float), np.asarray(L, int)


def _contents_counter(scenario: Scenario, station: Station, target_placement):
    """The supervisor's contents counter of the task (`tg_drake.tasks.judge.contents_counter`):
    pourOut counts the target's spheres in the target and the bowl, pourIn the dispenser's in
    the target; None when the station has no such spheres."""
    task = scenario.task.task
    source = {"pourOut": target_placement.instance_name, "pourIn": "dispenser"}.get(task)
    model = next((m for m in station.contents if m.name == source), None)
    if model is None:
        return None
    names = [target_placement.instance_name]
    if task == "pourOut" and scenario.task.pour_into:
        names.append(scenario.task.pour_into)
    placements = {p.instance_name: p for p in scenario.objects}
    containers = {n: (int(station.object_body(n).index()), get_object(placements[n].id))
                  for n in names}
    return contents_counter(model, containers=containers,
                            table_z=float(scenario.X_WT.GetDeterministicValue().translation()[2]))


def add_pipeline(builder: DiagramBuilder, *, scenario: Scenario,
                 config: PipelineConfig | None = None) -> Pipeline:
    """Adds the station and every stage of `scenario` to `builder`, wired as in the module doc."""
    config = config or scenario.pipeline
    config.validate()
    station = add_station(builder, scenario=scenario)
    target_placement = scenario.target_placement()
    X_WO_target = placement_pose(scenario, target_placement)

    # Perception: the rendered depth image of one camera, or the library's ground truth.
    if isinstance(config.perception, DepthPerception):
        camera = config.perception.camera
        if camera not in station.cameras:
            raise unknown_name("camera", camera, list(station.cameras),
                               error=ScenarioError, field="pipeline.perception.camera")
        # The scenario's random_seed seeds perception's RANSAC too (added to the config's seed,
        # so that both settings are honoured; both 0 by default).
        perception_config = config.perception.config
        perception_config = dataclasses.replace(perception_config, segmentation=dataclasses.replace(
            perception_config.segmentation,
            seed=perception_config.segmentation.seed + scenario.random_seed))
        perception = builder.AddNamedSystem("perception", PerceptionSystem(
            camera_info=station.cameras[camera].info, config=perception_config))
        # The camera's measurement of the rendered depth (perception.sensor), seeded by the
        # scenario's random_seed and the frame's capture index.
        camera_config = scenario.cameras[camera]
        depth_noise = builder.AddNamedSystem("depth_noise", DepthNoise(
            station.cameras[camera].info, config.perception.sensor, seed=scenario.random_seed,
            fps=camera_config.fps, capture_offset=camera_config.capture_offset))
        builder.Connect(station.outputs[f"{camera}.depth_image"], depth_noise.get_input_port())
        builder.Connect(depth_noise.get_output_port(), perception.GetInputPort("depth_image"))
        builder.Connect(station.outputs[f"{camera}.camera_pose"],
                        perception.GetInputPort("camera_pose"))
    else:
        perception = builder.AddNamedSystem("perception", GroundTruthPerception(
            [p.id for p in scenario.objects],
            [placement_pose(scenario, p) for p in scenario.objects],
            X_WT=scenario.X_WT.GetDeterministicValue(),
            poses=[p.pose for p in scenario.objects],
            containments=[p.containment for p in scenario.objects],
            spacing=config.perception.spacing, seed=scenario.random_seed,
            body_indices=[int(station.object_body(p.instance_name).index())
                          for p in scenario.objects]))
        # Looking again (after a place-and-regrasp leg) describes the objects where they are.
        builder.Connect(station.outputs["body_poses"], perception.GetInputPort("body_poses"))
    # The user points at the target's middle (its box centre; its frame's origin is at its base).
    target = builder.AddNamedSystem("target", TargetSelector(
        X_WO_target.multiply(box_centre(target_placement.id))))
    builder.Connect(perception.GetOutputPort("scene_description"),
                    target.GetInputPort("scene_description"))
    scene = target.get_output_port()

    # Category prior, logic, grasp scoring.
    prior = builder.AddNamedSystem("kernel_prior", KernelPriorSystem(config.prior_config()))
    builder.Connect(scene, prior.GetInputPort("scene_description"))
    logic = builder.AddNamedSystem("logic", LogicQuerySystem(config.logic))
    task = builder.AddNamedSystem("task", TaskSource(scenario.task.task))
    builder.Connect(scene, logic.GetInputPort("scene_description"))
    builder.Connect(prior.GetOutputPort("category_prior"), logic.GetInputPort("category_prior"))
    builder.Connect(task.get_output_port(), logic.GetInputPort("task"))
    scoring = builder.AddNamedSystem("dgi_scoring", DgiScoringSystem(
        load_model(config.scoring.model) if config.scoring.model else None,
        selection=config.selection, part=getattr(config.scoring, "part", None),
        expansion=config.expansion, approach=config.planner.pregrasp_distance,
        seed=getattr(config.scoring, "seed", 0)))
    builder.Connect(scene, scoring.GetInputPort("scene_description"))
    builder.Connect(logic.GetOutputPort("grasp_semantics"),
                    scoring.GetInputPort("grasp_semantics"))

    # Planner and execution; the supervisor closes the loop back to the logic and judges.
    supervision = config.supervisor
    X_WT = scenario.X_WT.GetDeterministicValue()
    place_xy_W = (X_WT @ np.array([*scenario.task.place_xy, 0.0, 1.0]))[:2]
    # Feasibility: the scored poses, with collisions and P(hold); the planner plans them.
    feasibility = builder.AddNamedSystem("feasibility", GraspFeasibility(
        config.feasibility, approach=config.planner.pregrasp_distance))
    builder.Connect(scene, feasibility.GetInputPort("scene_description"))
    builder.Connect(logic.GetOutputPort("grasp_semantics"),
                    feasibility.GetInputPort("grasp_semantics"))
    builder.Connect(scoring.GetOutputPort("ranked_grasps"),
                    feasibility.GetInputPort("ranked_grasps"))
    ranked = feasibility.GetOutputPort("ranked_grasps")
    # The task's placing: a resting pose to turn the object into, or a surface to put it on.
    surfaces = surfaces_in_world(scenario.surfaces, X_WT.GetAsMatrix4())
    surface = place_surface(scenario)
    pour_at = None  # the bowl's box centre, as the user points at it
    for placement in scenario.objects:
        if scenario.task.pour_into and placement.instance_name == scenario.task.pour_into:
            pour_at = placement_pose(scenario, placement).multiply(box_centre(placement.id))[:2]
    fill_at = None  # pourIn: under the dispenser's gate; its hopper is an obstacle
    if scenario.dispenser is not None:
        X_WH = dispenser_frame(scenario).GetAsMatrix4()
        d = scenario.dispenser
        fill_at = X_WH[:3, 3] - X_WH[:3, 2] * DISPENSER_WALL  # the gate's underside
        surfaces.append(dispenser_obstacle(
            X_WH, side=d.width + 2 * DISPENSER_WALL, below=DISPENSER_WALL,
            above=hopper_height(d, d.sphere_radius(scenario.contents)) + DISPENSER_WALL))
    placing = task_placing(scenario.task.task, place_xy=place_xy_W, pour_at=pour_at,
                           fill_at=fill_at, table_z=float(X_WT.translation()[2]),
                           surface=next((s for s in surfaces if surface is not None
                                         and s.name == surface.name), None),
                           config=config.tasks)
    planner = builder.AddNamedSystem("planner", GraspPlanner(
        place_xy=place_xy_W, start_time=supervision.planning_start + supervision.period,
        config=config.planner, scenario=scenario, placing=placing, surfaces=surfaces,
        handover=handover_of(scenario), feasibility=config.feasibility))
    builder.Connect(scene, planner.GetInputPort("scene_description"))
    builder.Connect(ranked, planner.GetInputPort("ranked_grasps"))
    builder.Connect(station.outputs["iiwa.state"], planner.GetInputPort("iiwa.state"))
    builder.Connect(planner.GetOutputPort("iiwa.desired_state"),
                    station.inputs["iiwa.desired_state"])
    builder.Connect(planner.GetOutputPort("wsg.position"), station.inputs["wsg.position"])
    if "receiver.mount" in station.inputs:  # a pass: the receiver follows the plan's hand-over
        shape = Surface(*sample_surface(target_placement.id, spacing=RECEIVER_SURFACE_SPACING,
                                        rng=np.random.default_rng(0))[:2])
        receiver = builder.AddNamedSystem("receiver_driver", ReceiverDriver(
            handover_of(scenario),
            object_body=int(station.object_body(target_placement.instance_name).index()),
            surface=shape))
        builder.Connect(planner.GetOutputPort("plan_status"), receiver.GetInputPort("plan_status"))
        builder.Connect(station.outputs["body_poses"], receiver.GetInputPort("body_poses"))
        for name in ("receiver.mount", "receiver.position"):
            builder.Connect(receiver.GetOutputPort(name), station.inputs[name])
        builder.Connect(logic.GetOutputPort("grasp_semantics"),
                        planner.GetInputPort("grasp_semantics"))

    plant = station.plant
    supervisor = builder.AddNamedSystem("supervisor", Supervisor(
        config=supervision, model=MonitorModel.from_plant(
            plant, object_body=station.object_body(target_placement.instance_name),
            wsg_instance=station.instances["wsg"], table_instance=station.instances["table"],
            p_OC=box_centre(target_placement.id), X_WT=X_WT.GetAsMatrix4(),
            is_tool=get_object(target_placement.id).is_tool,
            surfaces=[(s.name, surface_body_name(s.name)) for s in scenario.surfaces],
            receiver_instance=station.instances.get("receiver"),
            part_vertices=(_part_vertices(target_placement.id)
                           if "receiver" in station.instances else None)),
        task=scenario.task.task, place_on=surface.name if surface is not None else "",
        pour_into=scenario.task.pour_into, container=target_placement.instance_name,
        count_contents=_contents_counter(scenario, station, target_placement),
        dispense_duration=config.tasks.fill_open))
    if "dispenser.open" in station.inputs:
        builder.Connect(supervisor.GetOutputPort("dispenser_command"),
                        station.inputs["dispenser.open"])
    builder.Connect(scene, supervisor.GetInputPort("scene_description"))
    builder.Connect(logic.GetOutputPort("grasp_semantics"),
                    supervisor.GetInputPort("grasp_semantics"))
    builder.Connect(ranked, supervisor.GetInputPort("ranked_grasps"))
    builder.Connect(planner.GetOutputPort("plan_status"), supervisor.GetInputPort("plan_status"))
    for name in ("wsg.state", "body_poses", "contact_results"):
        builder.Connect(station.outputs[name], supervisor.GetInputPort(name))
    if "receiver.state" in station.outputs:
        builder.Connect(station.outputs["receiver.state"],
                        supervisor.GetInputPort("receiver.state"))
    builder.Connect(supervisor.GetOutputPort("collisions"), logic.GetInputPort("collisions"))
    builder.Connect(supervisor.GetOutputPort("no_hold"), logic.GetInputPort("no_hold"))
    builder.Connect(supervisor.GetOutputPort("plan_request"), planner.GetInputPort("plan_request"))
    # Legs (place-and-regrasp): the supervisor asks perception to look again, waits for the new
    # latch, and tells the target selector where the target was put.
    builder.Connect(supervisor.GetOutputPort("perception_request"),
                    perception.GetInputPort("perception_request"))
    builder.Connect(perception.GetOutputPort("perception_status"),
                    supervisor.GetInputPort("perception_status"))
    builder.Connect(supervisor.GetOutputPort("target_xy"), target.GetInputPort("target_xy"))

    ports = {"scene_description": scene,
             "category_prior": prior.GetOutputPort("category_prior"),
             "grasp_semantics": logic.GetOutputPort("grasp_semantics"),
             "scored_grasps": scoring.GetOutputPort("ranked_grasps"),
             "ranked_grasps": ranked,
             "plan_status": planner.GetOutputPort("plan_status"),
             "collisions": supervisor.GetOutputPort("collisions"),
             "no_hold": supervisor.GetOutputPort("no_hold"),
             "plan_request": supervisor.GetOutputPort("plan_request"),
             "outcome": supervisor.GetOutputPort("outcome")}
    return Pipeline(station=station, perception=perception, target=target, prior=prior,
                    logic=logic, scoring=scoring, feasibility=feasibility, planner=planner,
                    supervisor=supervisor,
                    task=task, config=config, ports=ports)
