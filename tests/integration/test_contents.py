"""Contents as spheres in physics: every sphere accounted for, none through a wall.

A full cup standing on the table keeps its spheres (asleep once they rest, awake again when the
cup is pushed); the same cup turned upside down above the table by a test rig (the cup welded to
a link on a PD-driven revolute joint) pours them all onto the table; the dispenser drops its
spheres into an empty bowl standing below it, and keeps them while its gate is closed (opened
while they sleep on it, it wakes them). Counts are those of `count_contents`, the task check's;
a sphere that leaves the table lands on the floor, which touches nothing else.
"""

import numpy as np
import pytest
from pydrake.geometry import Role
from pydrake.math import RigidTransform
from pydrake.multibody.math import SpatialVelocity
from pydrake.multibody.tree import BodyIndex
from pydrake.systems.analysis import Simulator

from tg_drake.objects import WATER_DENSITY, get_object
from tg_drake.scenario import load_scenario
from tg_drake.simulation.pour import tilt_rig
from tg_drake.simulation.sleep import ContentsSleep, advance
from tg_drake.station import CONTENTS_FLOOR, CONTENTS_WALL, make_station
from tg_drake.table import TABLE_HEIGHT, X_WT_DEFAULT
from tg_drake.tasks.contents import ContentsConfig, count_contents

CUP = "cup_01"
BOWL = "bowl_01"
FULL_CUP = f"""
objects: [{{id: {CUP}, xy: [0.0, 0.2], containment: full}}]
contents: {{model: spheres}}
cameras: {{}}
"""  # a full cup of spheres on the table, no camera


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
    scenario = load_scenario(scenario_text=FULL_CUP)
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


def _sphere_positions(station, context):
    plant = station.plant
    plant_context = plant.GetMyContextFromRoot(context)
    return np.array([plant.EvalBodyPoseInWorld(plant_context, plant.get_body(BodyIndex(b)))
                     .translation() for m in station.contents for b in m.bodies])


def test_resting_spheres_sleep_where_they_lie_and_wake_when_their_cup_is_pushed():
    scenario = load_scenario(scenario_text=FULL_CUP)
    diagram, station = make_station(scenario)
    (model,) = station.contents
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    _hold_robot(diagram, station, context)
    sleeper = ContentsSleep.for_station(station, scenario.contents)
    advance(simulator, 1.5, sleeper)  # settled within 0.75 s, then still for sleep_after
    assert sleeper.asleep and [e for _, e in sleeper.events] == ["sleep"]
    p_asleep = _sphere_positions(station, context)
    advance(simulator, 2.0, sleeper)
    assert np.array_equal(_sphere_positions(station, context), p_asleep)  # locked where they lay
    # Pushed sideways at 0.5 m/s: the next step wakes them, and they stay in the cup.
    plant = station.plant
    plant.SetFreeBodySpatialVelocity(plant.GetMyMutableContextFromRoot(context),
                                     station.object_body(CUP),
                                     SpatialVelocity(w=[0.0, 0.0, 0.0], v=[0.5, 0.0, 0.0]))
    advance(simulator, 2.005, sleeper)
    assert not sleeper.asleep and sleeper.events[-1] == (2.005, "wake")
    advance(simulator, 3.0, sleeper)
    (counts,) = _station_counts(diagram, station, context, {CUP: CUP})
    assert counts == {CUP: len(model.bodies), "table": 0, "floor": 0, "elsewhere": 0}
    assert not np.array_equal(_sphere_positions(station, context), p_asleep)


def test_without_sleep_the_spheres_never_sleep():
    scenario = load_scenario(scenario_text=FULL_CUP.replace(
        "contents: {model: spheres}", "contents: {model: spheres, sleep: false}"))
    assert scenario.contents.sleep is False
    diagram, station = make_station(scenario)
    simulator = Simulator(diagram)
    _hold_robot(diagram, station, simulator.get_mutable_context())
    sleeper = ContentsSleep.for_station(station, scenario.contents)
    advance(simulator, 1.5, sleeper)
    assert not sleeper.asleep and sleeper.events == []


def test_a_sphere_shot_out_of_the_workspace_is_frozen_where_it_strayed():
    scenario = load_scenario(scenario_text=FULL_CUP)
    diagram, station = make_station(scenario)
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    _hold_robot(diagram, station, context)
    plant = station.plant
    plant_context = plant.GetMyMutableContextFromRoot(context)
    sphere = plant.get_body(BodyIndex(station.contents[0].bodies[0]))
    # Shot up at 30 m/s from 1.9 m above the table top: out of the workspace (2 m) within a step.
    plant.SetFreeBodyPose(plant_context, sphere, RigidTransform([0.75, 0.0, 1.9]))
    plant.SetFreeBodySpatialVelocity(plant_context, sphere,
                                     SpatialVelocity(w=[0.0, 0.0, 0.0], v=[0.0, 0.0, 30.0]))
    sleeper = ContentsSleep.for_station(station, scenario.contents)
    advance(simulator, 0.05, sleeper)  # the first check
    assert sleeper.frozen == {0} and sleeper.events == [(0.05, "froze 1 strayed")]
    p_frozen = plant.EvalBodyPoseInWorld(plant_context, sphere).translation()
    assert p_frozen[2] > 2.0
    advance(simulator, 1.5, sleeper)  # the others sleep and wake around it; it stays
    assert np.array_equal(plant.EvalBodyPoseInWorld(plant_context, sphere).translation(),
                          p_frozen)
    (counts,) = _station_counts(diagram, station, context, {CUP: CUP})
    assert counts["elsewhere"] == 1 and counts[CUP] == len(station.contents[0].bodies) - 1


def test_the_spheres_touch_the_simplified_wall_and_everything_else_the_original_mesh():
    scenario = load_scenario(scenario_text=FULL_CUP)
    _, station = make_station(scenario)
    plant, inspector = station.plant, station.scene_graph.model_inspector()
    (model,) = station.contents
    body = station.object_body(CUP)
    names = {inspector.GetName(g): g for g in plant.GetCollisionGeometriesForBody(body)}
    (wall,) = [g for n, g in names.items() if n.endswith(CONTENTS_WALL)]
    original = names[inspector.GetName(wall).removesuffix(f"_{CONTENTS_WALL}")]
    sphere = plant.GetCollisionGeometriesForBody(plant.get_body(BodyIndex(model.bodies[0])))[0]
    pad = next(g for g in inspector.GetAllGeometryIds()
               if "finger" in inspector.GetName(g) and inspector.GetProximityProperties(g))
    assert not inspector.CollisionFiltered(sphere, wall)
    assert inspector.CollisionFiltered(sphere, original)
    assert not inspector.CollisionFiltered(pad, original)
    assert inspector.CollisionFiltered(pad, wall)
    assert inspector.GetPoseInFrame(wall).IsExactlyEqualTo(inspector.GetPoseInFrame(original))


def test_a_sphere_off_the_table_lands_on_the_floor_which_touches_nothing_else():
    scenario = load_scenario(scenario_text=FULL_CUP)
    diagram, station = make_station(scenario)
    plant, inspector = station.plant, station.scene_graph.model_inspector()
    (floor,) = [g for g in inspector.GetAllGeometryIds(Role.kProximity)
                if inspector.GetName(g).endswith(CONTENTS_FLOOR)]
    spheres = [g for b in station.contents[0].bodies
               for g in plant.GetCollisionGeometriesForBody(plant.get_body(BodyIndex(b)))]
    touched = [g for g in inspector.GetAllGeometryIds(Role.kProximity)
               if g != floor and not inspector.CollisionFiltered(floor, g)]
    assert sorted(touched) == sorted(spheres)
    # One sphere beside the table (0.2 m past its far edge), 0.1 m above its top.
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    _hold_robot(diagram, station, context)
    sphere = plant.get_body(BodyIndex(station.contents[0].bodies[0]))
    x_far = X_WT_DEFAULT.translation()[0] + 0.5 * scenario.table_size[0] + 0.2
    plant_context = plant.GetMyMutableContextFromRoot(context)
    plant.SetFreeBodyPose(plant_context, sphere, RigidTransform([x_far, 0.0, 0.1]))
    simulator.AdvanceTo(1.0)  # falls 0.5 m in 0.32 s, then rests on the floor
    z = plant.EvalBodyPoseInWorld(plant_context, sphere).translation()[2]
    radius = station.contents[0].radius
    assert z == pytest.approx(-TABLE_HEIGHT + radius, abs=0.5 * radius)
    (counts,) = _station_counts(diagram, station, context, {CUP: CUP})
    assert counts["floor"] == 1 and counts[CUP] == len(station.contents[0].bodies) - 1


def test_the_mass_model_adds_no_spheres():
    scenario = load_scenario(scenario_text=f"""
objects: [{{id: {CUP}, xy: [0.0, 0.2], containment: full}}]
cameras: {{}}
""")
    _, station = make_station(scenario)
    assert station.contents == []
    assert station.plant.HasBodyNamed(f"{CUP}_contents")


def _rig_counts(rig, simulator):
    return rig.counts(simulator.get_mutable_context())


@pytest.mark.slow
def test_a_cup_turned_upside_down_pours_every_sphere_onto_the_table():
    rig = tilt_rig(CUP, ContentsConfig(model="spheres"))
    simulator = Simulator(rig.diagram)
    n = len(rig.model.bodies)
    assert _rig_counts(rig, simulator) == {CUP: n, "table": 0, "floor": 0, "elsewhere": 0}
    simulator.AdvanceTo(2.5)
    assert _rig_counts(rig, simulator) == {CUP: 0, "table": n, "floor": 0, "elsewhere": 0}


@pytest.mark.slow
def test_a_cup_tilted_short_of_its_rim_keeps_every_sphere():
    # 30° from upright: the spheres' level stays below the rim.
    rig = tilt_rig(CUP, ContentsConfig(model="spheres"), turn=np.deg2rad(30.0), duration=0.5)
    simulator = Simulator(rig.diagram)
    simulator.AdvanceTo(1.0)
    n = len(rig.model.bodies)
    assert _rig_counts(rig, simulator) == {CUP: n, "table": 0, "floor": 0, "elsewhere": 0}


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


def test_a_gate_opened_under_sleeping_spheres_wakes_them_and_they_fall_into_the_bowl():
    scenario = _dispenser_scenario()
    diagram, station = make_station(scenario)
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    _hold_robot(diagram, station, context)
    gate = diagram.GetInputPort("dispenser.open")
    gate.FixValue(context, [0.0])
    sleeper = ContentsSleep.for_station(station, scenario.contents)
    advance(simulator, 1.5, sleeper)
    assert sleeper.asleep
    gate.FixValue(context, [1.0])
    advance(simulator, 3.0, sleeper)
    assert "wake" in [e for _, e in sleeper.events]
    (counts,) = _station_counts(diagram, station, context, {BOWL: BOWL})
    assert counts == {BOWL: 12, "table": 0, "floor": 0, "elsewhere": 0}


def test_the_camera_sees_a_full_cup_of_spheres_as_a_full_cup_of_water():
    # The spheres are drawn in Meshcat only: perception sees the same image for either model.
    images = []
    for model in ("mass", "spheres"):
        scenario = load_scenario(scenario_text=f"""
objects: [{{id: {CUP}, xy: [0.0, 0.0], containment: full}}]
contents: {{model: {model}}}
""")
        diagram, station = make_station(scenario)
        context = diagram.CreateDefaultContext()
        images.append(np.array(diagram.GetOutputPort("camera0.depth_image").Eval(context).data))
    assert np.isfinite(images[0]).any()
    assert np.array_equal(images[0], images[1], equal_nan=True)
