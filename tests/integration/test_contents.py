"""Contents as spheres in physics: every sphere accounted for, none through a wall.

A full cup standing on the table keeps its spheres; the same cup turned upside down above the
table by a test rig (the cup welded to a link on a PD-driven revolute joint) pours them all onto
the table; the dispenser drops its spheres into an empty bowl standing below it, and keeps them
while its gate is closed. Counts are those of `count_contents`, the task check's.
"""

import numpy as np
import pytest
from pydrake.math import RigidTransform
from pydrake.multibody.plant import AddMultibodyPlant
from pydrake.multibody.tree import (
    BodyIndex,
    FixedOffsetFrame,
    PdControllerGains,
    RevoluteJoint,
    SpatialInertia,
)
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from tg_drake.models import make_parser
from tg_drake.objects import WATER_DENSITY, get_object, mesh
from tg_drake.scenario import default_plant_config, load_scenario
from tg_drake.station import add_spheres, make_station
from tg_drake.table import TABLE_SIZE, add_table
from tg_drake.tasks.contents import ContentsConfig, ContentsModel, container_sites, \
    count_contents

CUP = "cup_01"
BOWL = "bowl_01"


def _hold_robot(diagram, station, context):
    plant_context = station.plant.GetMyContextFromRoot(context)
    q = station.plant.GetPositions(plant_context, station.instances["iiwa"])
    diagram.GetInputPort("iiwa.desired_state").FixValue(context, np.concatenate([q, 0 * q]))
    diagram.GetInputPort("wsg.position").FixValue(context, [0.1])


def _station_counts(diagram, station, context, containers):
    plant = station.plant
    plant_context = plant.GetMyContextFromRoot(context)
    poses = diagram.GetOutputPort("body_poses").Eval(context)
    where = {name: (plant.EvalBodyPoseInWorld(plant_context, station.object_body(name)),
                    get_object(obj_id)) for name, obj_id in containers.items()}
    return [count_contents(m, poses, containers=where, table_z=0.0) for m in station.contents]


def test_a_full_cup_standing_for_1_s_keeps_every_sphere():
    scenario = load_scenario(scenario_text=f"""
objects: [{{id: {CUP}, xy: [0.0, 0.2], containment: full}}]
contents: {{model: spheres}}
cameras: {{}}
""")
    diagram, station = make_station(scenario)
    (model,) = station.contents
    assert model.name == CUP and len(model.bodies) > 0
    # The spheres weigh what the water does.
    plant = station.plant
    mass = sum(plant.get_body(BodyIndex(b)).default_mass() for b in model.bodies)
    assert mass == pytest.approx(WATER_DENSITY * get_object(CUP).cavity_volume, rel=1e-9)
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    _hold_robot(diagram, station, context)
    (before,) = _station_counts(diagram, station, context, {CUP: CUP})
    assert before[CUP] == len(model.bodies)
    simulator.AdvanceTo(1.0)
    (after,) = _station_counts(diagram, station, context, {CUP: CUP})
    assert after == {CUP: len(model.bodies), "table": 0, "floor": 0, "elsewhere": 0}


def test_the_mass_model_adds_no_spheres():
    scenario = load_scenario(scenario_text=f"""
objects: [{{id: {CUP}, xy: [0.0, 0.2], containment: full}}]
cameras: {{}}
""")
    _, station = make_station(scenario)
    assert station.contents == []
    assert station.plant.HasBodyNamed(f"{CUP}_contents")


def pour_rig(obj_id: str, config: ContentsConfig, *, pivot_height: float = 0.25,
             turn: float = np.pi, duration: float = 1.0):
    """A plant with the table, the container welded to a link on a revolute joint about the
    world x axis through a point `pivot_height` [m] above the table's centre (the container's
    base 5 cm below it), and its spheres; the joint follows a ramp from 0 to `turn` [rad] over
    `duration` [s] through the plant's PD control (gravity off for the rig and the container, as
    if a robot held it)."""
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlant(default_plant_config(), builder)
    X_WT = RigidTransform([0.75, 0.0, 0.0])
    add_table(plant, TABLE_SIZE, X_WT)
    obj = get_object(obj_id)
    (instance,) = make_parser(plant).AddModels(url=obj.sdf_url)
    body = plant.get_body(plant.GetBodyIndices(instance)[0])
    link = plant.AddRigidBody("rig_link", instance, SpatialInertia.SolidBoxWithMass(
        1.0, 0.05, 0.05, 0.05))
    X_WP = RigidTransform(X_WT.translation() + [0.0, 0.0, pivot_height])
    pivot = plant.AddFrame(FixedOffsetFrame("rig_pivot", plant.world_frame(), X_WP))
    joint = plant.AddJoint(RevoluteJoint("rig_joint", pivot, link.body_frame(), [1.0, 0.0, 0.0]))
    X_LO = RigidTransform([0.0, 0.0, -0.05])
    plant.WeldFrames(link.body_frame(), body.body_frame(), X_LO)
    actuator = plant.AddJointActuator("rig_actuator", joint, 200.0)
    actuator.set_controller_gains(PdControllerGains(p=200.0, d=20.0))
    plant.set_gravity_enabled(instance, False)
    V, F = mesh(obj)[:2]
    p_O = container_sites(obj.id, V, F, config)
    p_W = p_O + (X_WP @ X_LO).translation()
    spheres = plant.AddModelInstance("spheres")
    bodies = add_spheres(plant, spheres, "sphere", p_W, config.radius,
                         WATER_DENSITY * obj.cavity_volume / len(p_O), config)
    plant.Finalize()
    ramp = PiecewisePolynomial.FirstOrderHold([0.0, duration, duration + 100.0],
                                              [[0.0, turn, turn]])
    source = builder.AddSystem(TrajectorySource(ramp, output_derivative_order=1))
    builder.Connect(source.get_output_port(), plant.get_desired_state_input_port(instance))
    diagram = builder.Build()
    return diagram, plant, body, ContentsModel(obj.id, bodies, config.radius)


def _rig_counts(diagram, plant, body, model, context):
    plant_context = plant.GetMyContextFromRoot(context)
    poses = plant.get_body_poses_output_port().Eval(plant_context)
    X_WO = plant.EvalBodyPoseInWorld(plant_context, body)
    return count_contents(model, poses, containers={model.name: (X_WO, get_object(model.name))},
                          table_z=0.0)


@pytest.mark.slow
def test_a_cup_turned_upside_down_pours_every_sphere_onto_the_table():
    diagram, plant, body, model = pour_rig(CUP, ContentsConfig(model="spheres"))
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    assert _rig_counts(diagram, plant, body, model, context)[CUP] == len(model.bodies)
    simulator.AdvanceTo(2.5)
    counts = _rig_counts(diagram, plant, body, model, context)
    assert counts == {CUP: 0, "table": len(model.bodies), "floor": 0, "elsewhere": 0}


def test_a_cup_tilted_short_of_its_rim_keeps_every_sphere():
    # 30° from upright: the spheres' level stays below the rim.
    diagram, plant, body, model = pour_rig(CUP, ContentsConfig(model="spheres"),
                                           turn=np.deg2rad(30.0), duration=0.5)
    simulator = Simulator(diagram)
    simulator.AdvanceTo(1.0)
    counts = _rig_counts(diagram, plant, body, model, simulator.get_mutable_context())
    assert counts == {CUP: len(model.bodies), "table": 0, "floor": 0, "elsewhere": 0}


def _dispenser_scenario():
    return load_scenario(scenario_text=f"""
objects: [{{id: {BOWL}, xy: [0.1, 0.3]}}]
dispenser: {{xy: [0.1, 0.3], height: 0.15, count: 12}}
cameras: {{}}
""")


@pytest.mark.parametrize("open_gate", [True, False])
def test_the_dispenser_drops_its_spheres_into_the_bowl_below_only_when_open(open_gate):
    diagram, station = make_station(_dispenser_scenario())
    (model,) = station.contents
    assert model.name == "dispenser" and len(model.bodies) == 12
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    _hold_robot(diagram, station, context)
    diagram.GetInputPort("dispenser.open").FixValue(context, [1.0 if open_gate else 0.0])
    simulator.AdvanceTo(1.5)
    (counts,) = _station_counts(diagram, station, context, {BOWL: BOWL})
    if open_gate:
        assert counts == {BOWL: 12, "table": 0, "floor": 0, "elsewhere": 0}
    else:
        assert counts == {BOWL: 0, "table": 0, "floor": 0, "elsewhere": 12}
